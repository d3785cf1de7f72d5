// DiscBlock<L>: up to L discs in structure-of-arrays form (centre, decoded normal, squared
// radius, id): the leaf block of a BlockedWideBVH over discs, tested against one ray with
// one SIMD op per field and no gathers or per-disc normal decoding. DiscBlockIntersector
// tests such blocks with the same arithmetic as DiscIntersector, so that full-detail
// images through the wide BVH equal those through the LoD kd-tree.
#pragma once
#include "core/accel/wide_bvh.h"
#include "points/disc_intersector.h"
#include "points/ray_disc_plane.h"

namespace rtfact::points {

template <int L>
struct alignas(L * 4) DiscBlock {
    using Element = Disc;
    static constexpr int kSize = L;
    float c[3][L];  // centre[axis][lane]
    float n[3][L];  // unit normal (decoded once here)
    float r2[L];
    int32_t id[L];

    // Lanes from input indices ids[0..n); disc(i) returns input disc i. Unused lanes
    // repeat the last disc (same id, same result).
    template <class Get>
    void fill(const uint32_t* ids, int count, const Get& disc) {
        for (int i = 0; i < L; ++i) {
            const uint32_t k = ids[std::min(i, count - 1)];
            const Disc& d = disc(k);
            const Vec3f nn = d.n();
            for (int a = 0; a < 3; ++a) {
                c[a][i] = d.center[a];
                n[a][i] = nn[a];
            }
            r2[i] = d.radius * d.radius;
            id[i] = int32_t(k);
        }
    }
};
static_assert(LeafBlock<DiscBlock<8>> && LeafBlock<DiscBlock<16>>);

struct DiscBlockIntersector {
    template <int N>
    using Hit = DiscIntersector::Hit<N>;

    // Single discs (ElementIntersector): as DiscIntersector.
    template <HitData D, int N>
    RTFACT_INLINE void intersect(const Disc& d, uint32_t id, const RayPacket<N>& rays, Hit<N>& hit,
                                 int firstChunk) const {
        DiscIntersector{}.intersect<D>(d, id, rays, hit, firstChunk);
    }

    template <HitData D, int L>
    RTFACT_INLINE void intersectBlocks(const DiscBlock<L>* blocks, int count, const RayPacket<1>& ray,
                                       Hit<1>& hit) const {
        using P = Packet<L>;
        for (int k = 0; k < count; ++k) {
            P t;
            const auto m = blockTest(blocks[k], ray, float(hit.t), t);
            if (none(m)) continue;
            const P tm = select(m, t, P(kInfinity));
            const float best = hmin(tm);
            hit.t = best;
            hit.id = blocks[k].id[BitMask<L>(tm == P(best)).first()];
        }
    }
    // Any hit in (tMin, hit.t): records it in hit and returns true.
    template <int L>
    RTFACT_INLINE bool occludedBlocks(const DiscBlock<L>* blocks, int count, const RayPacket<1>& ray,
                                      Hit<1>& hit) const {
        return firstBlockHit<L>(blocks, count, hit, [&](const DiscBlock<L>& b, Packet<L>& t) {
            return blockTest(b, ray, float(hit.t), t);
        });
    }

   private:
    // One ray against L discs: DiscIntersector::intersectDisc with the disc in the lanes.
    template <int L>
    static RTFACT_INLINE auto blockTest(const DiscBlock<L>& b, const RayPacket<1>& ray, float tFar, Packet<L>& t) {
        using P = Packet<L>;
        const RayDiscPlane<L> h = rayDiscPlane(b.c, b.n, ray);
        t = h.t;
        return (h.dist2 <= P::load(b.r2)) & (t > P(float(ray.tMin))) & (t < P(tFar));
    }
};
static_assert(ElementIntersector<DiscBlockIntersector, Disc>);

// The full-detail part of the LoD wide BVH (points/lod_wide_bvh.h): a 16-wide BVH with
// leaves of one 8-disc block. 16 wide on every ISA (two 8-lane ops per slab on AVX2):
// the tree, and so the LoD image, is then the same on every machine.
inline constexpr int kDiscWideArity = 16;
inline constexpr int kDiscLeafBlock = 8;
using DiscWideBVH = BlockedWideBVH<DiscBlock<kDiscLeafBlock>, kDiscWideArity>;

}  // namespace rtfact::points
