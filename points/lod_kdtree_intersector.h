// LoDKdTreeIntersector<ElemIsect>: the core's generic kd-tree traversal with two hooks:
// children's cells clipped to their stored (quantised) bounds, which also covers discs
// reaching across split planes, and
// level-of-detail cuts: when a node's representative disc is smaller than the ray
// footprint at its distance times `quality`, the packet intersects that disc instead of
// descending. The footprint is the camera's cone, width(t) = base + slope * t, measured
// from the packet's origin (pinhole packets share one; other packets take the nearest
// live lane's: no lane is cut coarser than alone).
#pragma once
#include <array>
#include <cmath>

#include "core/accel/kdtree_intersector.h"
#include "core/concepts/camera.h"
#include "core/concepts/intersector_hooks.h"
#include "points/disc_intersector.h"
#include "points/lod_kdtree.h"

namespace rtfact::points {

template <class ElemIsect>
struct LoDNodeIntersector {
    ElemIsect elem{};
    const LoDInner* inner = nullptr;
    RayCone cone{};
    float quality = 1.0f;  // 0: full detail
    // Radius a representative is hit with, relative to its covering radius: the covering
    // sphere is a loose bound (it puffs silhouettes), the cut test keeps using it.
    float repScale = 0.7f;  // dragon 32M, quality 4: +2.3 dB PSNR vs 1.0; 0.55 opens holes
    template <int N>
    using Hit = typename ElemIsect::template Hit<N>;

    void bind(const LoDKdTree& t) { inner = t.inner.data(); }

    template <HitData D, int N>
    RTFACT_INLINE void intersect(const Disc& d, uint32_t id, const RayPacket<N>& rays, Hit<N>& hit,
                                 int firstChunk) const {
        elem.template intersect<D>(d, id, rays, hit, firstChunk);
    }

    template <HitData D, class Tree, int N>
    RTFACT_INLINE bool innerNode(const Tree& tree, uint32_t node, const AABB&, const RayPacket<N>& rays, Hit<N>& hit,
                                 int firstChunk) const {
        if (quality <= 0.0f) return false;
        const uint32_t idx = LoDKdTree::innerIndex(tree.nodes[node]);
        const Disc& r = inner[idx].rep;
        auto tooLarge = [&](float dist2) {
            const float dist = std::max(std::sqrt(dist2) - r.radius, 0.0f);
            return 2.0f * r.radius > quality * (cone.base + cone.slope * dist);
        };
        // The first lane's origin first: live, its distance bounds the nearest live lane's
        // from above (dead, it can only make the cut finer), so the other lanes need
        // looking at only when it would cut.
        const int lane = firstChunk * Packet<N>::W;
        const Vec3f o(rays.org.x[lane], rays.org.y[lane], rays.org.z[lane]);
        if (tooLarge(dot(r.center - o, r.center - o))) return false;
        if (!rays.commonOrigin && tooLarge(nearestOrigin2(r.center, rays, hit, firstChunk))) return false;
        Disc h = r;
        h.radius *= repScale;
        elem.template intersect<D>(h, uint32_t(-int32_t(idx) - 2), rays, hit, firstChunk);
        return true;
    }

    // Squared distance from c to the nearest origin of the packet's live lanes, where the
    // cut of packets without a common origin (AO rays from hit points) is judged, so that
    // no lane is cut coarser than it would be alone: the first lane's origin standing for
    // all cut AO lanes across a depth edge coarse right next to their own surface, which
    // then occluded them (black pixels, more of them the larger the packet).
    template <int N>
    static RTFACT_INLINE float nearestOrigin2(Vec3f c, const RayPacket<N>& rays, const Hit<N>& hit, int firstChunk) {
        using PC = typename Packet<N>::ChunkPacket;
        PC m(kInfinity);
        for (int k = firstChunk; k < Packet<N>::C; ++k) {
            const PC dx = PC(c.x) - rays.org.x.chunk(k), dy = PC(c.y) - rays.org.y.chunk(k),
                     dz = PC(c.z) - rays.org.z.chunk(k);
            // finished and inactive lanes carry hit.t = -inf
            m = min(m, select(hit.t.chunk(k) > PC(-kInfinity), dx * dx + dy * dy + dz * dz, PC(kInfinity)));
        }
        return hmin(m);
    }

    template <class Tree>
    RTFACT_INLINE void childCells(const Tree& tree, uint32_t node, const AABB& cell, AABB& lo, AABB& hi) const {
        const uint32_t idx = LoDKdTree::innerIndex(tree.nodes[node]);
        const LoDInner& in = inner[idx];
        // The children's summaries are the next dependent misses (23% of a 32M LoD frame
        // waited on them): start both now, before the children's nodes arrive.
        // 40-byte entries: half of them straddle two cache lines.
        const char* l = reinterpret_cast<const char*>(&inner[idx + 1]);
        const char* r = reinterpret_cast<const char*>(&inner[in.rightInner]);
        __builtin_prefetch(l);
        __builtin_prefetch(l + sizeof(LoDInner) - 1);
        __builtin_prefetch(r);
        __builtin_prefetch(r + sizeof(LoDInner) - 1);
        lo = intersection(cell, in.box(0));
        hi = intersection(cell, in.box(1));
    }
};

// Both hooks must reach the traversal: without them LoD cuts and clipped cells would
// silently turn off.
static_assert(KdTreeInnerNodeHook<LoDNodeIntersector<DiscIntersector>, KdTree<Disc>, 1> &&
              KdTreeInnerNodeHook<LoDNodeIntersector<DiscIntersector>, KdTree<Disc>, simd::kNativeWidth> &&
              KdTreeInnerNodeHook<LoDNodeIntersector<DiscIntersector>, KdTree<Disc>, 64>);
static_assert(KdTreeChildCellsHook<LoDNodeIntersector<DiscIntersector>, KdTree<Disc>>);

template <class ElemIsect>
using LoDKdTreeIntersector = KdTreeIntersector<LoDNodeIntersector<ElemIsect>>;

}  // namespace rtfact::points
