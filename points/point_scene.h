// PointScene: a point cloud as a GeometryScene (core/concepts/scene.h), so that the
// core's generic integrators (eyelight, direct light with shadows, AO, Whitted and
// path tracing) render it. Hits come from one of two LoD structures: the wide BVH of SoA
// disc blocks with child representatives in the parents (default) or the LoD kd-tree;
// shading data from the disc or representative disc hit, coloured by the chosen colour
// mode.
#pragma once
#include "core/concepts/scene.h"
#include "core/render/tracer.h"
#include "points/disc_intersector.h"
#include "points/lod_kdtree_intersector.h"
#include "points/lod_wide_intersector.h"
#include "points/point_prepare.h"

namespace rtfact::points {

// Distinct colours for LoD levels: 0 = input points (grey), then blue..red as the
// representative covers larger subtrees.
inline Vec3f lodLevelColor(int level) {
    static const Vec3f pal[] = {{0.75f, 0.75f, 0.75f}, {0.2f, 0.35f, 1.0f}, {0.1f, 0.8f, 0.9f},  {0.2f, 0.85f, 0.3f},
                                {0.9f, 0.9f, 0.2f},    {1.0f, 0.55f, 0.1f}, {1.0f, 0.15f, 0.1f}, {0.9f, 0.2f, 0.9f}};
    return pal[std::min(level, 7)];
}

// Which structure a PointScene builds. Wide: one SIMD test per node for K children
// and per block of 8 discs, child representatives beside the node (rtfact-bench points
// --accel compares both). KdTree: binary, 16-ray packets, representatives in the node;
// the default: the wide BVH traces 1.2-1.5x faster but its SAH build is ~7x slower and
// takes ~3x the memory (docs/benchmarks.md), too much for the clouds users load.
enum class PointAccel { Wide, KdTree };

struct PointScene {
    PointAccel accel = PointAccel::KdTree;       // set before build()
    LoDWideSplit wideSplit = LoDWideSplit::Sah;  // set before build()
    LoDKdTree tree;                              // PointAccel::KdTree
    LoDWideBVH wide;                             // PointAccel::Wide
    Tracer<LoDKdTreeIntersector<DiscIntersector>> tracer;
    Tracer<LoDWideIntersector> wideTracer;
    ColorMode colorMode = ColorMode::Rgb;
    template <int N>
    using Hit = DiscIntersector::Hit<N>;

    // The LoD kd-tree builder's leaf size applies to the kd-tree only.
    void build(std::vector<Disc> discs, const LoDKdTreeBuilder& builder = {}) {
        tree = {};
        wide = {};
        if (accel == PointAccel::Wide)
            wide = buildLoDWideBVH(std::move(discs), wideSplit);
        else
            tree = builder.build(std::move(discs));
        tracer.isect.elem.bind(tree);
    }
    // Footprint of the camera rays and the LoD quality (0: full detail).
    void setLoD(RayCone cone, float quality, float repScale = 0.7f) {
        tracer.isect.elem.bind(tree);
        tracer.isect.elem.repScale = repScale;
        tracer.isect.elem.cone = cone;
        tracer.isect.elem.quality = quality;
        wideTracer.isect.repScale = repScale;
        wideTracer.isect.cone = cone;
        wideTracer.isect.quality = quality;
    }
    bool isWide() const { return accel == PointAccel::Wide; }
    // The input discs (kd-tree: in leaf order); ids >= 0 index them.
    const std::vector<Disc>& discs() const { return isWide() ? wide.elems : tree.elems; }
    size_t memoryBytes() const { return isWide() ? wide.memoryBytes() : tree.memoryBytes(); }
    double bytesPerPoint() const { return discs().empty() ? 0.0 : double(memoryBytes()) / double(discs().size()); }
    size_t nodeCount() const { return isWide() ? wide.nodes.size() : tree.nodes.size(); }
    AABB bounds() const { return isWide() ? wide.box : tree.box; }
    // The disc a hit id names (a representative's for ids <= -2), by value: the wide tree
    // assembles its representatives from two arrays.
    Disc disc(int32_t id) const {
        if (isWide()) return wide.disc(id);
        return id >= 0 ? tree.elems[size_t(id)] : tree.inner[size_t(-id - 2)].rep;
    }

    template <int N>
    Hit<N> intersect(const RayPacket<N>& rays, const Mask<N>& active) const {
        if (isWide()) return wideTracer.intersect(wide, rays, active);
        return tracer.intersect(tree, rays, active);
    }
    template <int N>
    Mask<N> occluded(const RayPacket<N>& rays, const Mask<N>& active) const {
        if (isWide()) return wideTracer.occluded(wide, rays, active);
        return tracer.occluded(tree, rays, active);
    }
    template <int N>
    SurfacePoint<N> surface(const RayPacket<N>& rays, const Hit<N>& hit, const Mask<N>& valid) const {
        SurfacePoint<N> sp;
        sp.p = rays.org + rays.dir * hit.t;
        Vec3<N> n(Vec3f(0, 0, 1)), col(Vec3f(1.0f));
        uint64_t reps = 0;
        for (int i = 0; i < N; ++i) {
            if (!valid[i]) continue;
            const int32_t id = hit.id[i];
            const Disc d = disc(id);
            reps += id < 0;
            Vec3f nn = d.n();
            Vec3f c;
            switch (colorMode) {
                case ColorMode::Normal:
                    c = nn * 0.5f + Vec3f(0.5f);
                    break;
                case ColorMode::Lod:
                    c = lodLevelColor(id < 0 ? d.level() : 0);
                    break;
                default:
                    c = unpackRGB(d.rgba);
                    break;
            }
            // The stored normal points outwards: a ray along it leaves the surface.
            if (dot(nn, rays.dir.lane(i)) > 0) {
                nn = -nn;
                sp.front.set(i, false);
            }
            n.setLane(i, nn);
            col.setLane(i, c);
        }
        tlsCounters.lodNodesHit += reps;
        sp.n = n;
        sp.ng = n;
        sp.u = Packet<N>(0.0f);
        sp.v = Packet<N>(0.0f);
        sp.color = col;
        sp.material = Packet<N, int32_t>(0);
        return sp;
    }
};
static_assert(GeometryScene<PointScene>);
static_assert(Intersector<LoDKdTreeIntersector<DiscIntersector>, KdTree<Disc>>);
static_assert(Intersector<LoDWideIntersector, LoDWideBVH>);

}  // namespace rtfact::points
