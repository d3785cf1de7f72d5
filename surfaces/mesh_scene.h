// MeshScene<Structure>: a triangle mesh as a GeometryScene, on the core's BVH or kd-tree
// with the generic packet intersectors around TriangleIntersector. Every core integrator
// (eyelight, direct light, AO, Whitted, path) renders it.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <type_traits>
#include <vector>

#include "core/accel/bvh_intersector.h"
#include "core/accel/in_place_sah_bvh_builder.h"
#include "core/accel/kdtree_intersector.h"
#include "core/accel/sah_bvh_builder.h"
#include "core/accel/sah_kdtree_builder.h"
#include "core/accel/wide_bvh_builder.h"
#include "core/accel/wide_bvh_intersector.h"
#include "core/accel/wide_bvh_packet_intersector.h"
#include "core/concepts/scene.h"
#include "core/render/secondary_rays.h"
#include "core/render/tracer.h"
#include "core/util/huge_pages.h"
#include "surfaces/mesh.h"
#include "surfaces/textures.h"
#include "surfaces/triangle.h"

namespace rtfact::surfaces {

// The triangles of a mesh in index order (triangle i = indices[3i..3i+2]).
inline std::vector<Triangle> meshTriangles(const Mesh& m) {
    std::vector<Triangle> t(m.triangles());
    for (size_t i = 0; i < t.size(); ++i)
        t[i] = {m.positions[m.indices[3 * i]], m.positions[m.indices[3 * i + 1]], m.positions[m.indices[3 * i + 2]]};
    return t;
}

// Bounds of triangle t of m.
inline AABB meshTriangleBox(const Mesh& m, size_t t) {
    const Vec3f a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                c = m.positions[m.indices[3 * t + 2]];
    return {vmin(vmin(a, b), c), vmax(vmax(a, b), c)};
}

// Bounds of the triangles in index order, computed in parallel on huge pages.
inline std::vector<AABB> meshTriangleBounds(const Mesh& m) {
    const size_t n = m.triangles();
    std::vector<AABB> bounds;
    resizeHugePages(bounds, n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16384), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) bounds[i] = meshTriangleBox(m, i);
    });
    return bounds;
}

template <class Structure>
struct MeshIntersectorFor;
template <>
struct MeshIntersectorFor<BVH<Triangle>> {
    using type = BVHIntersector<TriangleIntersector>;
};
template <>
struct MeshIntersectorFor<KdTree<Triangle>> {
    using type = KdTreeIntersector<TriangleIntersector>;
};

// The BVH builder used for meshes: in-place binned SAH; a traversal cost of twice a
// triangle test gives leaves of 2-4 triangles, which suits packets (a node test costs a
// slab test per chunk, a triangle test four dot products per chunk).
inline InPlaceSAHBVHBuilder meshBVHBuilder() {
    InPlaceSAHBVHBuilder b;
    b.maxLeafSize = 4;
    b.traversalCost = 2.0f;
    b.intersectionCost = 1.0f;
    return b;
}

// Arity of the wide BVH that serves incoherent single rays (one AVX/AVX-512 op per slab)
// and the width of its triangle leaf blocks (one AVX test per block). Measured with
// `rtfact-bench mesh --wide-variants` (docs/architecture.md): blocks of 8 beat blocks of
// 4 on AO rays, and 16-wide nodes beat 8-wide ones where one AVX-512 op tests them.
inline constexpr int kMeshWideArity = simd::kNativeWidth >= 16 ? 16 : 8;
inline constexpr int kMeshLeafBlock = 8;

// The wide BVH builder used for meshes: leaves costed in whole triangle blocks.
inline WideSAHBVHBuilder meshWideBVHBuilder() {
    WideSAHBVHBuilder b;
    b.leafBlock = kMeshLeafBlock;
    b.maxLeafSize = 4 * kMeshLeafBlock;
    return b;
}
using MeshWideBVH = BlockedWideBVH<TriangleBlock<kMeshLeafBlock>, kMeshWideArity>;

// The wide BVH of a mesh: built directly from the triangles' bounds, computed on the fly
// from the indexed mesh (no bounds array to fault in), then the leaves packed into
// triangle blocks straight from the mesh.
inline MeshWideBVH buildMeshWideBVH(const Mesh& m) {
    WideBVHTopology<kMeshWideArity> topo;
    meshWideBVHBuilder().build(
        uint32_t(m.triangles()), [&](uint32_t t) { return meshTriangleBox(m, t); }, topo);
    using Block = TriangleBlock<kMeshLeafBlock>;
    return packLeafBlocks<Block>(std::move(topo), [&](Block& b, const uint32_t* ids, int cnt) {
        b.fill(ids, cnt, [&](uint32_t t) {
            return Triangle{m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]],
                            m.positions[m.indices[3 * t + 2]]};
        });
    });
}

// Wide BVHs from this size on trace the lanes of incoherent packets interleaved
// (WideBVHIntersector::group). Measured on Zen 5 (32 MB L3, one thread, CPU time): on the
// 100k dragon (6.6 MB) interleaving 4 rays cost ~10% on AO and bounce rays, on the 1.1M
// and 2.5M triangle grids (100-230 MB) it gained 4-11%.
inline constexpr size_t kWideGroupMinBytes = size_t(32) << 20;

template <class Structure = BVH<Triangle>>
struct MeshScene {
    std::shared_ptr<const Mesh> mesh;
    Structure accel;
    Tracer<typename MeshIntersectorFor<Structure>::type> tracer;
    // Incoherent rays (AO, diffuse bounces) go one by one through a wide BVH built
    // directly with SIMD blocks of triangles as leaves (BVH scenes only; kd-tree scenes
    // answer them with `accel`).
    bool buildWide = true;  // set before build()
    // Coherent rays (primary, packet secondaries) take the binary packet BVH when it is
    // built, else the wide BVH's packet traversal (WideBVHPacketIntersector); coherent
    // shadow rays take the wide packets whenever the wide BVH exists (occluded()).
    // With the wide BVH the binary one is built only for meshes of at most
    // packetBVHMaxTriangles (default 0: never). Measured in session 20 (Zen 5, AVX-512 and
    // AVX2 builds, docs/benchmarks.md): the wide packets' primary rays are 1.13-1.37x
    // Embree's on every real scan (0.80-1.10x the binary BVH's; it wins on the smallest
    // meshes), their shadow rays 1.20-1.81x, and the wide build alone takes 0.56-0.84x
    // Embree's time at 2 threads and 0.68-0.78x its memory, where building both took
    // 1.5-2.1x its time and 1.4x its memory.
    size_t packetBVHMaxTriangles = 0;  // set before build()
    MeshWideBVH wide;
    Tracer<WideBVHIntersector<TriangleIntersector>> wideTracer;
    Tracer<WideBVHPacketIntersector<TriangleIntersector>> widePacketTracer;
    // When set, counts the rays the wide BVH answered: tests check that the wide path
    // really runs (null by default: one branch per query, no shared cache line).
    std::atomic<uint64_t>* wideRayCount = nullptr;
    std::vector<Vec3f> materialColor;       // diffuse colour per material id
    std::vector<ImageTexture> diffuseMaps;  // per material id (image empty: none)
    AABB box;
    template <int N>
    using Hit = TriangleIntersector::Hit<N>;

    MeshScene() = default;
    explicit MeshScene(std::shared_ptr<const Mesh> m) : mesh(std::move(m)) { build(); }

    void build() {
        if constexpr (std::is_same_v<Structure, BVH<Triangle>>) {
            // Straight from the indexed mesh into leaf order, on huge pages (no
            // intermediate triangle array: first-touch page faults dominate big builds).
            const Mesh& m = *mesh;
            const size_t n = m.triangles();
            accel = BVH<Triangle>{};
            wide = {};
            if (buildWide) wide = buildMeshWideBVH(m);
            if (buildWide && n > packetBVHMaxTriangles) return finishBuild();
            const std::vector<AABB> bounds = meshTriangleBounds(m);
            meshBVHBuilder().build(std::span<const AABB>(bounds), static_cast<BVHTopology&>(accel));
            resizeHugePages(accel.elems, n);
            tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16384), [&](const tbb::blocked_range<size_t>& r) {
                for (size_t i = r.begin(); i != r.end(); ++i) {
                    const uint32_t t = accel.order[i];
                    accel.elems[i] = {m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]],
                                      m.positions[m.indices[3 * t + 2]]};
                }
            });
        } else {
            const std::vector<Triangle> tris = meshTriangles(*mesh);
            accel = buildKdTree<Triangle>(SAHKdTreeBuilder{}, std::span<const Triangle>(tris));
        }
        finishBuild();
    }
    void finishBuild() {
        box = mesh->bounds();
        wideTracer.isect.group = wide.memoryBytes() >= kWideGroupMinBytes ? wideTracer.isect.kMaxGroup : 1;
        materialColor.clear();
        diffuseMaps.clear();
        for (const MeshMaterial& mm : mesh->materials) {
            materialColor.push_back(mm.kd);
            ImageTexture t;
            // map_Kd images (meshes without uvs cannot use them).
            if (!mm.diffuseMap.empty() && !mesh->uvs.empty())
                t.image = std::make_shared<const Image>(readImage(mm.diffuseMap));
            diffuseMaps.push_back(t);
        }
    }
    AABB bounds() const { return box; }
    size_t memoryBytes() const { return accel.memoryBytes() + (hasWide() ? wide.memoryBytes() : 0); }
    bool hasWide() const { return !wide.nodes.empty(); }
    // Coherent queries go through the wide BVH (its packet traversal).
    bool coherentWide() const { return hasWide() && accel.nodes.empty(); }

    template <int N>
    Hit<N> intersect(const RayPacket<N>& rays, const Mask<N>& active) const {
        if (coherentWide()) return widePacketTracer.intersect(wide, rays, active);
        return tracer.intersect(accel, rays, active);
    }
    template <int N>
    Hit<N> intersectDistance(const RayPacket<N>& rays, const Mask<N>& active) const {
        if (coherentWide()) return widePacketTracer.template intersect<HitData::Distance>(wide, rays, active);
        return tracer.template intersect<HitData::Distance>(accel, rays, active);
    }
    // Shadow rays take the wide packets whenever the wide BVH exists: on the 100k dragon
    // too they were 1.07-1.21x the binary BVH's in every quiet run (session s6, AVX-512 and
    // AVX2 builds, 1 and 2 threads).
    template <int N>
    Mask<N> occluded(const RayPacket<N>& rays, const Mask<N>& active) const {
        if (hasWide()) return widePacketTracer.occluded(wide, rays, active);
        return tracer.occluded(accel, rays, active);
    }

    // Incoherent rays: lane by lane through the wide BVH when it exists.
    template <int N>
    Hit<N> intersectIncoherent(const RayPacket<N>& rays, const Mask<N>& active) const {
        if (hasWide()) {
            countWide(active);
            return wideTracer.intersect(wide, rays, active);
        }
        return tracer.intersect(accel, rays, active);
    }
    template <int N>
    Mask<N> occludedIncoherent(const RayPacket<N>& rays, const Mask<N>& active) const {
        if (hasWide()) {
            countWide(active);
            return wideTracer.occluded(wide, rays, active);
        }
        return tracer.occluded(accel, rays, active);
    }

    template <int N>
    void countWide(const Mask<N>& active) const {
        if (wideRayCount) wideRayCount->fetch_add(uint64_t(popcount(active)), std::memory_order_relaxed);
    }

    // Position, interpolated shading normal, geometric normal (both facing the ray),
    // uv, colour (vertex colour times material diffuse colour), material id and the
    // side the ray arrives from (triangle winding).
    template <int N>
    SurfacePoint<N> surface(const RayPacket<N>& rays, const Hit<N>& hit, const Mask<N>& valid) const {
        SurfacePoint<N> sp;
        sp.p = rays.org + rays.dir * hit.t;
        sp.n = Vec3<N>(Vec3f(0, 0, 1));
        sp.ng = sp.n;
        sp.u = Packet<N>(0.0f);
        sp.v = Packet<N>(0.0f);
        sp.color = Vec3<N>(Vec3f(1.0f));
        sp.material = Packet<N, int32_t>(0);
        const Mesh& m = *mesh;
        const bool hasUV = !m.uvs.empty(), hasColor = !m.colors.empty(), hasMat = !m.materialIds.empty();
        BitMask<N>(valid).forEach([&](int i) {
            const uint32_t t = uint32_t(hit.id[i]);
            const uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
            const float bu = hit.u[i], bv = hit.v[i], bw = 1.0f - bu - bv;
            const Vec3f d = rays.dir.lane(i);
            const Vec3f wound = cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]);
            // Closed meshes wind outwards: a ray along the wound normal leaves the object.
            sp.front.set(i, !(dot(wound, d) > 0.0f));
            Vec3f ng = normalize(wound);
            if (dot(ng, d) > 0.0f) ng = -ng;
            Vec3f n = normalize(m.normals[i0] * bw + m.normals[i1] * bu + m.normals[i2] * bv);
            if (dot(n, ng) < 0.0f) n = -n;
            sp.ng.setLane(i, ng);
            sp.n.setLane(i, n);
            if (hasUV) {
                sp.u[i] = m.uvs[2 * i0] * bw + m.uvs[2 * i1] * bu + m.uvs[2 * i2] * bv;
                sp.v[i] = m.uvs[2 * i0 + 1] * bw + m.uvs[2 * i1 + 1] * bu + m.uvs[2 * i2 + 1] * bv;
            } else {
                sp.u[i] = bu;
                sp.v[i] = bv;
            }
            // Meshes without materials get the default diffuse colour (MeshMaterial::kd).
            Vec3f col = hasMat ? Vec3f(1.0f) : MeshMaterial{}.kd;
            if (hasColor) col = col * (m.colors[i0] * bw + m.colors[i1] * bu + m.colors[i2] * bv);
            if (hasMat) {
                const int32_t mat = m.materialIds[t];
                sp.material[i] = mat;
                col = col * materialColor[size_t(mat)];
                if (hasUV && diffuseMaps[size_t(mat)].image)
                    col = col * diffuseMaps[size_t(mat)].sample(sp.u[i], sp.v[i]);
            }
            sp.color.setLane(i, col);
        });
        return sp;
    }
};
static_assert(GeometryScene<MeshScene<BVH<Triangle>>>);
static_assert(GeometryScene<MeshScene<KdTree<Triangle>>>);
// WideSecondaryRays reach the wide BVH only through these queries.
static_assert(IncoherentQueries<MeshScene<BVH<Triangle>>, 1> &&
              IncoherentQueries<MeshScene<BVH<Triangle>>, simd::kNativeWidth> &&
              IncoherentQueries<MeshScene<BVH<Triangle>>, 64>);
static_assert(Intersector<WideBVHIntersector<TriangleIntersector>, WideBVH<Triangle, kMeshWideArity>>);
static_assert(Intersector<WideBVHIntersector<TriangleIntersector>, MeshWideBVH>);
static_assert(Intersector<WideBVHPacketIntersector<TriangleIntersector>, MeshWideBVH>);

}  // namespace rtfact::surfaces
