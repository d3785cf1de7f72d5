// LoDKdTreeIntersector<ElemIsect>: the core's generic kd-tree traversal with two hooks:
// children's cells clipped to their stored (quantised) bounds, which also covers discs
// reaching across split planes, and
// level-of-detail cuts: when a node's representative disc is smaller than the ray
// footprint at its distance times `quality`, the packet intersects that disc instead of
// descending. The footprint is the camera's cone, width(t) = base + slope * t, measured
// from the packet's first active ray origin (exact for pinhole packets, which share it).
#pragma once
#include <array>

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
        const int lane = firstChunk * Packet<N>::W;
        const Vec3f o(rays.org.x[lane], rays.org.y[lane], rays.org.z[lane]);
        const float dist = std::max(length(r.center - o) - r.radius, 0.0f);
        if (2.0f * r.radius > quality * (cone.base + cone.slope * dist)) return false;
        Disc h = r;
        h.radius *= repScale;
        elem.template intersect<D>(h, uint32_t(-int32_t(idx) - 2), rays, hit, firstChunk);
        return true;
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
