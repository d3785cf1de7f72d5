// Triangle and its intersector: one generic routine for single rays and packets.
//
// The test is Plücker-style on vertices relative to the ray origin: each edge (p -> q)
// yields the edge function dot(cross(q - p, p + q), d). Computed from the difference
// and the sum of its end points, the value of a shared edge is bit-exactly negated in
// the neighbouring triangle (which walks the edge the other way), whatever FMA
// contraction the compiler picks, so a ray on a shared edge hits at least one of the
// two triangles: no cracks. Vertices, where the spoke values of a whole fan are
// rounding noise, are closed by a tiny relative tolerance. With a common origin (primary rays, shadow rays cast from
// a light) the edge vectors are scalar per triangle and each chunk only needs four dot
// products (three edges and the plane).
#pragma once
#include <algorithm>
#include <cstring>
#include <utility>

#include "core/accel/wide_bvh_intersector.h"
#include "core/accel/wide_bvh_packet_intersector.h"
#include "core/concepts/intersector.h"
#include "core/concepts/intersector_hooks.h"
#include "core/simd/bitmask.h"

namespace rtfact::surfaces {

// Compact layout: the three vertices (36 bytes); the normal is recomputed per test
// (a handful of scalar operations, cheaper than the extra memory traffic).
struct Triangle {
    Vec3f v0, v1, v2;
    AABB bounds() const {
        AABB b;
        b.extend(v0).extend(v1).extend(v2);
        return b;
    }
};
static_assert(Primitive<Triangle>);
static_assert(sizeof(Triangle) == 36);

// Edge function vector of the edge p -> q (twice q x p), symmetric in the sense above.
template <class V>
RTFACT_INLINE V triangleEdge(const V& p, const V& q) {
    return cross(q - p, p + q);
}

// The (unnormalised) normal (v1 - v0) x (v2 - v0) every triangle test uses, of one
// triangle (Vec3f) or of SIMD lanes of triangles (Vec3<L>).
template <class V>
RTFACT_INLINE V faceNormal(const V& v0, const V& v1, const V& v2) {
    return cross(v1 - v0, v2 - v0);
}

// Up to L triangles in structure-of-arrays form (vertex, axis, lane) with their ids: the
// leaf block of a BlockedWideBVH, tested with one SIMD edge-function test and no
// gathers. Unused lanes repeat the last triangle (same id, same result).
template <int L>
struct alignas(L * 4) TriangleBlock {
    using Element = Triangle;
    static constexpr int kSize = L;
    float v[3][3][L];  // v[vertex][axis][lane]
    int32_t id[L];

    // Lanes from input indices ids[0..n); tri(i) returns input triangle i.
    template <class Get>
    void fill(const uint32_t* ids, int n, const Get& tri) {
        for (int i = 0; i < L; ++i) {
            const uint32_t k = ids[std::min(i, n - 1)];
            const Triangle t = tri(k);
            const Vec3f* vs[3] = {&t.v0, &t.v1, &t.v2};
            for (int j = 0; j < 3; ++j)
                for (int a = 0; a < 3; ++a) v[j][a][i] = (*vs[j])[a];
            id[i] = int32_t(k);
        }
    }
};
static_assert(LeafBlock<TriangleBlock<4>> && LeafBlock<TriangleBlock<8>>);

struct TriangleIntersector {
    template <int N>
    struct Hit {
        Packet<N> t;
        Packet<N, int32_t> id;
        Packet<N> u, v;  // barycentric weights of v1 and v2
    };

    template <HitData D, int N>
    RTFACT_INLINE void intersect(const Triangle& tri, uint32_t id, const RayPacket<N>& rays, Hit<N>& hit,
                                 int firstChunk) const {
        intersectChunks<D>(tri, id, rays, hit, firstChunk, Packet<N>::C);
    }

    // The first n triangles of a block (the rest is padding) against chunk k of a packet
    // (the wide BVH's packet path): the same per-triangle arithmetic as intersect, so
    // both structures give the same hits.
    template <HitData D, int L, int N>
    RTFACT_INLINE void intersectBlockChunk(const TriangleBlock<L>& b, int n, const RayPacket<N>& rays, Hit<N>& hit,
                                           int k) const {
        if (rays.commonOrigin) {
            // The block's edge vectors, normals and plane numerators in one SIMD pass (as
            // intersectBlockLanes computes them; the per-triangle test gets the same values
            // one triangle at a time), then each triangle's lane against the chunk.
            Vec3<L> a, bb, c;
            blockRelative(b, Vec3f(rays.org.x[0], rays.org.y[0], rays.org.z[0]), a, bb, c);
            const Vec3<L> nn = blockNormal(b);
            const Vec3<L> e[4] = {triangleEdge(bb, c), triangleEdge(c, a), triangleEdge(a, bb), nn};
            alignas(64) float v[13][L];  // e0, e1, e2, n (x, y, z each), then tnum
            for (int j = 0; j < 4; ++j)
                for (int a3 = 0; a3 < 3; ++a3) e[j][a3].store(v[3 * j + a3]);
            dot(nn, a).store(v[12]);
            for (int i = 0; i < n; ++i)
                commonOriginChunk<D>(Vec3f(v[0][i], v[1][i], v[2][i]), Vec3f(v[3][i], v[4][i], v[5][i]),
                                     Vec3f(v[6][i], v[7][i], v[8][i]), Vec3f(v[9][i], v[10][i], v[11][i]), v[12][i],
                                     uint32_t(b.id[i]), rays, hit, k, k + 1);
            return;
        }
        for (int i = 0; i < n; ++i) {
            const Triangle t{Vec3f(b.v[0][0][i], b.v[0][1][i], b.v[0][2][i]),
                             Vec3f(b.v[1][0][i], b.v[1][1][i], b.v[1][2][i]),
                             Vec3f(b.v[2][0][i], b.v[2][1][i], b.v[2][2][i])};
            intersectChunks<D>(t, uint32_t(b.id[i]), rays, hit, k, k + 1);
        }
    }

    // Lanes `lanes` of chunk k against a block, each lane with one SIMD test over the
    // block's triangles (the single-ray block arithmetic). With a common origin the edge
    // functions of the block are computed once for all lanes, and a lane costs four dot
    // products. Returns the lanes (bits of chunk k) that found a closer hit.
    template <HitData D, int L, int N>
    RTFACT_INLINE uint32_t intersectBlockLanes(const TriangleBlock<L>& b, const RayPacket<N>& rays, Hit<N>& hit, int k,
                                               uint32_t lanes) const {
        using P = Packet<L>;
        constexpr int W = Packet<N>::W;
        uint32_t found = 0;
        auto lane = [&](int i, const Vec3<L>& a, const Vec3<L>& nn, const Vec3<L>& e0v, const Vec3<L>& e1v,
                        const Vec3<L>& e2v) __attribute__((always_inline)) {
            const Vec3<L> d(Vec3f(rays.dir.x[i], rays.dir.y[i], rays.dir.z[i]));
            const P e0 = dot(e0v, d), e1 = dot(e1v, d), e2 = dot(e2v, d);
            const auto inside = edgesAgree(e0, e1, e2);
            if (none(inside)) return;
            const P nd = dot(nn, d);
            const P t = dot(nn, a) / nd;
            const auto m = inside & (nd != P(0.0f)) & (t > P(float(rays.tMin[i]))) & (t < P(float(hit.t[i])));
            if (none(m)) return;
            Hit<1> h;
            takeNearest<D>(m, t, e0, e1, e2, b.id, h);
            hit.t[i] = h.t;
            hit.id[i] = h.id;
            if constexpr (D == HitData::Shading) {
                hit.u[i] = h.u;
                hit.v[i] = h.v;
            }
            found |= 1u << (i - k * W);
        };
        const Vec3<L> nn = blockNormal(b);  // origin-free: once per block
        if (rays.commonOrigin) {
            Vec3<L> a, bb, c;
            blockRelative(b, Vec3f(rays.org.x[0], rays.org.y[0], rays.org.z[0]), a, bb, c);
            const Vec3<L> e0v = triangleEdge(bb, c), e1v = triangleEdge(c, a), e2v = triangleEdge(a, bb);
            for (uint32_t r = lanes; r; r &= r - 1) lane(k * W + __builtin_ctz(r), a, nn, e0v, e1v, e2v);
        } else {
            for (uint32_t r = lanes; r; r &= r - 1) {
                const int i = k * W + __builtin_ctz(r);
                Vec3<L> a, bb, c;
                blockRelative(b, Vec3f(rays.org.x[i], rays.org.y[i], rays.org.z[i]), a, bb, c);
                lane(i, a, nn, triangleEdge(bb, c), triangleEdge(c, a), triangleEdge(a, bb));
            }
        }
        return found;
    }

    // Lanes of chunk k whose edge functions e0, e1, e2 agree and whose plane distance
    // (plane() gives (tnum, nd), computed only once some lane is inside) lies in range
    // take triangle id. The distance comes from the plane equation (tnum / dot(n, d)), not
    // from the edge sum: edge functions of a small triangle far from the origin lose many
    // bits.
    template <HitData D, int N, int W, class Plane>
    static RTFACT_INLINE void finishChunk(int k, const Packet<W>& e0, const Packet<W>& e1, const Packet<W>& e2,
                                          const Plane& plane, uint32_t id, const RayPacket<N>& rays, Hit<N>& hit) {
        using P = Packet<W>;
        using PI = Packet<W, int32_t>;
        const auto inside = edgesAgree(e0, e1, e2);
        if (none(inside)) return;
        const auto [tnum, nd] = plane();
        const P t = tnum / nd;
        P& th = hit.t.chunk(k);
        const auto m = inside & (nd != P(0.0f)) & (t > rays.tMin.chunk(k)) & (t < th);
        if (none(m)) return;
        th = select(m, t, th);
        hit.id.chunk(k) = select(m, PI(int32_t(id)), hit.id.chunk(k));
        if constexpr (D == HitData::Shading) {
            const P inv = P(1.0f) / (e0 + e1 + e2);
            hit.u.chunk(k) = select(m, e1 * inv, hit.u.chunk(k));
            hit.v.chunk(k) = select(m, e2 * inv, hit.v.chunk(k));
        }
    }
    // Chunks [firstChunk, endChunk) of a common-origin packet against one triangle given
    // by its edge vectors, normal and plane numerator relative to the origin.
    template <HitData D, int N>
    static RTFACT_INLINE void commonOriginChunk(const Vec3f& e0f, const Vec3f& e1f, const Vec3f& e2f, const Vec3f& n,
                                                float tnumf, uint32_t id, const RayPacket<N>& rays, Hit<N>& hit,
                                                int firstChunk, int endChunk) {
        constexpr int W = Packet<N>::W;
        using P = Packet<W>;
        const Vec3<W> e0(e0f), e1(e1f), e2(e2f), nn(n);
        const P tnum(tnumf);
        for (int k = firstChunk; k < endChunk; ++k) {
            const Vec3<W> d = rays.dir.chunk(k);
            finishChunk<D>(
                k, dot(e0, d), dot(e1, d), dot(e2, d), [&] { return std::pair<P, P>(tnum, dot(nn, d)); }, id, rays,
                hit);
        }
    }

    // Chunks [firstChunk, endChunk) of the packet against one triangle.
    template <HitData D, int N>
    RTFACT_INLINE void intersectChunks(const Triangle& tri, uint32_t id, const RayPacket<N>& rays, Hit<N>& hit,
                                       int firstChunk, int endChunk) const {
        constexpr int W = Packet<N>::W;
        using P = Packet<W>;
        const Vec3f n = faceNormal(tri.v0, tri.v1, tri.v2);
        if (rays.commonOrigin) {
            const Vec3f o(rays.org.x[0], rays.org.y[0], rays.org.z[0]);
            const Vec3f a = tri.v0 - o, b = tri.v1 - o, c = tri.v2 - o;
            commonOriginChunk<D>(triangleEdge(b, c), triangleEdge(c, a), triangleEdge(a, b), n, dot(n, a), id, rays,
                                 hit, firstChunk, endChunk);
        } else {
            const Vec3<W> v0(tri.v0), v1(tri.v1), v2(tri.v2), nn(n);
            for (int k = firstChunk; k < endChunk; ++k) {
                const Vec3<W> o = rays.org.chunk(k), d = rays.dir.chunk(k);
                const Vec3<W> a = v0 - o, b = v1 - o, c = v2 - o;
                finishChunk<D>(
                    k, dot(triangleEdge(b, c), d), dot(triangleEdge(c, a), d), dot(triangleEdge(a, b), d),
                    [&] { return std::pair<P, P>(dot(nn, a), dot(nn, d)); }, id, rays, hit);
            }
        }
    }

    // A whole leaf against one ray (the wide BVH's single-ray path): the triangles of
    // the leaf fill the SIMD lanes, kLeafLanes at a time, with the same edge functions.
    static constexpr int kLeafLanes = 8;
    template <HitData D>
    RTFACT_INLINE void intersectLeaf(const Triangle* tris, const uint32_t* ids, int count, const RayPacket<1>& ray,
                                     Hit<1>& hit) const {
        constexpr int L = kLeafLanes;
        using P = Packet<L>;
        const Vec3f of(ray.org.x[0], ray.org.y[0], ray.org.z[0]);
        const Vec3<L> d(Vec3f(ray.dir.x[0], ray.dir.y[0], ray.dir.z[0]));
        for (int base = 0; base < count; base += L) {
            const int n = std::min(L, count - base);
            auto tri = [&](int i) -> const Triangle& { return tris[base + std::min(i, n - 1)]; };  // pad: the last
            Vec3<L> a, b, c;
            for (int i = 0; i < L; ++i) {
                a.setLane(i, tri(i).v0 - of);
                b.setLane(i, tri(i).v1 - of);
                c.setLane(i, tri(i).v2 - of);
            }
            P e0, e1, e2, t;
            const auto m = laneTest(a, b, c, d, float(ray.tMin), float(hit.t), e0, e1, e2, t, [&] {
                Vec3<L> nn;
                for (int i = 0; i < L; ++i) nn.setLane(i, faceNormal(tri(i).v0, tri(i).v1, tri(i).v2));
                return nn;
            });
            if (!none(m)) takeNearest<D>(m, t, e0, e1, e2, ids + base, hit);
        }
    }

    // Blocks of a BlockedWideBVH leaf: the same arithmetic as intersectLeaf, loaded
    // straight from structure-of-arrays. Where two blocks fill one native SIMD op
    // (AVX-512, blocks of 8) they are tested as one: the same per-lane values, and the
    // nearest (first on ties) lane is the one the block-by-block test would keep.
    template <HitData D, int L>
    RTFACT_INLINE void intersectBlocks(const TriangleBlock<L>* blocks, int n, const RayPacket<1>& ray,
                                       Hit<1>& hit) const {
        int k = 0;
        if constexpr (kPairBlocks<L>) {
            for (; k + 1 < n; k += 2) {
                Packet<2 * L> e0, e1, e2, t;
                const auto m = pairTest(blocks[k], blocks[k + 1], ray, float(hit.t), e0, e1, e2, t);
                if (!none(m)) {
                    int32_t ids[2 * L];
                    std::memcpy(ids, blocks[k].id, sizeof(blocks[k].id));
                    std::memcpy(ids + L, blocks[k + 1].id, sizeof(blocks[k].id));
                    takeNearest<D>(m, t, e0, e1, e2, ids, hit);
                }
            }
        }
        for (; k < n; ++k) {
            Packet<L> e0, e1, e2, t;
            const auto m = blockTest(blocks[k], ray, float(hit.t), e0, e1, e2, t);
            if (!none(m)) takeNearest<D>(m, t, e0, e1, e2, blocks[k].id, hit);
        }
    }
    // Any hit in (tMin, hit.t): records it in hit and returns true (the first hit lane of
    // the first block with one, paired or not).
    template <int L>
    RTFACT_INLINE bool occludedBlocks(const TriangleBlock<L>* blocks, int n, const RayPacket<1>& ray,
                                      Hit<1>& hit) const {
        int k = 0;
        if constexpr (kPairBlocks<L>) {
            for (; k + 1 < n; k += 2) {
                Packet<2 * L> e0, e1, e2, t;
                const auto m = pairTest(blocks[k], blocks[k + 1], ray, float(hit.t), e0, e1, e2, t);
                if (none(m)) continue;
                const int lane = BitMask<2 * L>(m).first();
                hit.t = t[lane];
                hit.id = lane < L ? blocks[k].id[lane] : blocks[k + 1].id[lane - L];
                return true;
            }
        }
        return firstBlockHit<L>(blocks + k, n - k, hit, [&](const TriangleBlock<L>& b, Packet<L>& t) {
            Packet<L> e0, e1, e2;
            return blockTest(b, ray, float(hit.t), e0, e1, e2, t);
        });
    }

   private:
    template <int L>
    static constexpr bool kPairBlocks = 2 * L <= simd::kNativeWidth;

    // Lanes [0, L) from a, [L, 2L) from b, as one packet.
    template <int L>
    static RTFACT_INLINE Packet<2 * L> pairLoad(const float* a, const float* b) {
        using P2 = Packet<2 * L>;
        P2 r;
        if constexpr (P2::C == 2) {
            r.c[0] = Packet<L>::load(a).c[0];
            r.c[1] = Packet<L>::load(b).c[0];
        } else {
            r.c[0] = concatChunks(Packet<L>::load(a).c[0], Packet<L>::load(b).c[0], std::make_index_sequence<2 * L>{});
        }
        return r;
    }
    template <class V, size_t... I>
    static RTFACT_INLINE auto concatChunks(V x, V y, std::index_sequence<I...>) {
        return __builtin_shufflevector(x, y, I...);
    }
    // Blocks a and b against one ray as 2L lanes (blockTest's arithmetic).
    template <int L>
    static RTFACT_INLINE auto pairTest(const TriangleBlock<L>& a, const TriangleBlock<L>& b, const RayPacket<1>& ray,
                                       float tFar, Packet<2 * L>& e0, Packet<2 * L>& e1, Packet<2 * L>& e2,
                                       Packet<2 * L>& t) {
        constexpr int L2 = 2 * L;
        using P = Packet<L2>;
        const float o[3] = {ray.org.x[0], ray.org.y[0], ray.org.z[0]};
        Vec3<L2> v[3];
        for (int j = 0; j < 3; ++j)
            v[j] = Vec3<L2>(pairLoad<L>(a.v[j][0], b.v[j][0]) - P(o[0]), pairLoad<L>(a.v[j][1], b.v[j][1]) - P(o[1]),
                            pairLoad<L>(a.v[j][2], b.v[j][2]) - P(o[2]));
        const Vec3<L2> d(Vec3f(ray.dir.x[0], ray.dir.y[0], ray.dir.z[0]));
        return laneTest(v[0], v[1], v[2], d, float(ray.tMin), tFar, e0, e1, e2, t, [&] {
            Vec3<L2> w[3];
            for (int j = 0; j < 3; ++j)
                w[j] = Vec3<L2>(pairLoad<L>(a.v[j][0], b.v[j][0]), pairLoad<L>(a.v[j][1], b.v[j][1]),
                                pairLoad<L>(a.v[j][2], b.v[j][2]));
            return faceNormal(w[0], w[1], w[2]);
        });
    }
    // The normals of a block's triangles, from the stored vertices.
    template <int L>
    static RTFACT_INLINE Vec3<L> blockNormal(const TriangleBlock<L>& b) {
        using P = Packet<L>;
        Vec3<L> w[3];
        for (int j = 0; j < 3; ++j) w[j] = Vec3<L>(P::load(b.v[j][0]), P::load(b.v[j][1]), P::load(b.v[j][2]));
        return faceNormal(w[0], w[1], w[2]);
    }
    // The vertices of a block's triangles relative to origin o, as loaded from the block.
    template <int L>
    static RTFACT_INLINE void blockRelative(const TriangleBlock<L>& b, const Vec3f& o, Vec3<L>& a, Vec3<L>& bb,
                                            Vec3<L>& c) {
        using P = Packet<L>;
        const P ox(o.x), oy(o.y), oz(o.z);
        a = Vec3<L>(P::load(b.v[0][0]) - ox, P::load(b.v[0][1]) - oy, P::load(b.v[0][2]) - oz);
        bb = Vec3<L>(P::load(b.v[1][0]) - ox, P::load(b.v[1][1]) - oy, P::load(b.v[1][2]) - oz);
        c = Vec3<L>(P::load(b.v[2][0]) - ox, P::load(b.v[2][1]) - oy, P::load(b.v[2][2]) - oz);
    }
    template <int L>
    static RTFACT_INLINE auto blockTest(const TriangleBlock<L>& b, const RayPacket<1>& ray, float tFar, Packet<L>& e0,
                                        Packet<L>& e1, Packet<L>& e2, Packet<L>& t) {
        const Vec3<L> d(Vec3f(ray.dir.x[0], ray.dir.y[0], ray.dir.z[0]));
        Vec3<L> a, bb, c;
        blockRelative(b, Vec3f(ray.org.x[0], ray.org.y[0], ray.org.z[0]), a, bb, c);
        // The normal reloads the vertices (the barrier stops the compiler from keeping the
        // first loads live across the edge test, which spills them on AVX2).
        return laneTest(a, bb, c, d, float(ray.tMin), tFar, e0, e1, e2, t, [&] {
            asm volatile("" ::: "memory");
            return blockNormal(b);
        });
    }
    // The lanes whose three edge functions agree in sign. A tolerance of 2^-16 of the
    // edge magnitudes closes vertices, where several near-zero spoke values of one fan
    // may all round to the same side.
    template <class P>
    static RTFACT_INLINE auto edgesAgree(const P& e0, const P& e1, const P& e2) {
        const P tol = (abs(e0) + abs(e1) + abs(e2)) * P(1.0f / 65536.0f);
        return (min(min(e0, e1), e2) >= -tol) | (max(max(e0, e1), e2) <= tol);
    }
    // One ray against L triangles given relative to the ray origin (a, b, c): the same
    // watertight edge functions as the per-triangle test; the lanes hit in (tMin, tFar).
    // normal() gives the triangles' faceNormal from the stored vertices. The plane and t
    // are computed whether or not some lane is inside: a branch on the edge test
    // mispredicts on most blocks a ray hits, and costs more than the dozen operations it
    // saves (session 33, Zen 5, both ISAs: AO rays +8-10%, bounces +5-8% against Embree).
    template <int L, class Normal>
    static RTFACT_INLINE auto laneTest(const Vec3<L>& a, const Vec3<L>& b, const Vec3<L>& c, const Vec3<L>& d,
                                       float tMin, float tFar, Packet<L>& e0, Packet<L>& e1, Packet<L>& e2,
                                       Packet<L>& t, const Normal& normal) {
        using P = Packet<L>;
        e0 = dot(triangleEdge(b, c), d);
        e1 = dot(triangleEdge(c, a), d);
        e2 = dot(triangleEdge(a, b), d);
        const auto inside = edgesAgree(e0, e1, e2);
        // The per-triangle test's values: n from the stored (not origin-relative)
        // vertices, so t matches it bit for bit, also for grazing rays where t is
        // ill-conditioned.
        const Vec3<L> nn = normal();
        const P nd = dot(nn, d);
        t = dot(nn, a) / nd;
        return inside & (nd != P(0.0f)) & (t > P(tMin)) & (t < P(tFar));
    }
    // Records the nearest lane of mask m (not empty) in hit; ids[lane] is its triangle.
    template <HitData D, int L, class Mk, class Id>
    static RTFACT_INLINE void takeNearest(const Mk& m, const Packet<L>& t, const Packet<L>& e0, const Packet<L>& e1,
                                          const Packet<L>& e2, const Id* ids, Hit<1>& hit) {
        const Packet<L> tm = select(m, t, Packet<L>(kInfinity));
        const float best = hmin(tm);
        const int lane = BitMask<L>(tm == Packet<L>(best)).first();
        hit.t = best;
        hit.id = int32_t(ids[lane]);
        if constexpr (D == HitData::Shading) {
            const float inv = 1.0f / (e0[lane] + e1[lane] + e2[lane]);
            hit.u = e1[lane] * inv;
            hit.v = e2[lane] * inv;
        }
    }
};
static_assert(ElementIntersector<TriangleIntersector, Triangle>);
// The wide BVH tests whole leaves through this hook (else one triangle at a time).
static_assert(LeafIntersector<TriangleIntersector, Triangle>);
// ... and SIMD blocks of triangles in a BlockedWideBVH.
static_assert(BlockIntersector<TriangleIntersector, TriangleBlock<4>> &&
              BlockIntersector<TriangleIntersector, TriangleBlock<8>>);
// ... and blocks per packet chunk (the wide BVH's packet traversal).
static_assert(PacketBlockIntersector<TriangleIntersector, TriangleBlock<4>> &&
              PacketBlockIntersector<TriangleIntersector, TriangleBlock<8>>);

}  // namespace rtfact::surfaces
