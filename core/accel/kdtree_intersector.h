// Generic packet traversal of a KdTree<Elem>. Each stack entry carries its cell, so
// every lane's interval is recomputed exactly with the shared slab test; lanes whose
// hit lies before a cell drop out, and cells are visited near to far. An element
// intersector may answer an inner node itself (level-of-detail cuts, KdTreeInnerNodeHook)
// and give the children's cells itself when its elements reach beyond the split plane
// (KdTreeChildCellsHook); both hooks are named in core/concepts/intersector_hooks.h.
// An empty `indices` list means the elements are stored in leaf order (first..first+count).
#pragma once
#include <new>

#include "core/accel/kdtree.h"
#include "core/accel/ray_box.h"
#include "core/concepts/intersector.h"
#include "core/concepts/intersector_hooks.h"
#include "core/util/assert.h"

namespace rtfact {

template <class ElemIsect>
struct KdTreeIntersector {
    ElemIsect elem{};
    template <int N>
    using Hit = typename ElemIsect::template Hit<N>;

    template <bool CommonOrigin, HitData D, class Elem, int N>
    void intersect(const KdTree<Elem>& tree, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        hit.t = select(active, rays.tMax, Packet<N>(-kInfinity));
        hit.id = Packet<N, int32_t>(-1);
        traverse<CommonOrigin, D, false>(tree, rays, hit, active);
        hit.t = select(active, hit.t, rays.tMax);
    }

    template <bool CommonOrigin, class Elem, int N>
    Mask<N> occluded(const KdTree<Elem>& tree, const RayPacket<N>& rays, const Mask<N>& active) const {
        Hit<N> hit;
        hit.t = select(active, rays.tMax, Packet<N>(-kInfinity));
        hit.id = Packet<N, int32_t>(-1);
        traverse<CommonOrigin, HitData::Distance, true>(tree, rays, hit, active);
        return active & (hit.id != Packet<N, int32_t>(-1));
    }

   private:
    static constexpr int kStackSize = 256;

    template <bool CommonOrigin, HitData D, bool AnyHit, class Elem, int N>
    void traverse(const KdTree<Elem>& tree, const RayPacket<N>& rays, Hit<N>& hit, const Mask<N>& active) const {
        if (tree.nodes.empty()) return;
        constexpr int C = Packet<N>::C;
        constexpr int W = Packet<N>::W;
        struct Entry {
            AABB cell;
            uint32_t node, first;
        };
        // Raw storage: AABB's default constructor would fill all 8 KB on every packet.
        alignas(Entry) unsigned char storage[sizeof(Entry) * kStackSize];
        Entry* stack = reinterpret_cast<Entry*>(storage);
        int sp = 0;
        new (&stack[sp++]) Entry{tree.box, 0u, 0u};
        while (sp > 0) {
            const Entry e = stack[--sp];
            int k = int(e.first);
            while (k < C && none(chunkHitsBox<CommonOrigin>(e.cell.lo, e.cell.hi, rays, hit.t, k))) ++k;
            if (k == C) continue;
            const KdNode& node = tree.nodes[e.node];
            if (node.isLeaf()) {
                if (tree.indices.empty()) {
                    for (uint32_t i = node.first(), end = node.first() + node.count; i < end; ++i)
                        elem.template intersect<D>(tree.elems[i], i, rays, hit, k);
                } else {
                    const uint32_t* ids = tree.indices.data() + node.first();
                    for (uint32_t i = 0; i < node.count; ++i)
                        elem.template intersect<D>(tree.elems[ids[i]], ids[i], rays, hit, k);
                }
                if constexpr (AnyHit) {
                    const Mask<N> found = hit.id != Packet<N, int32_t>(-1);
                    hit.t = select(found, Packet<N>(-kInfinity), hit.t);
                    if (all(found | ~active)) return;
                }
                continue;
            }
            if constexpr (KdTreeInnerNodeHook<ElemIsect, KdTree<Elem>, N>) {
                if (elem.template innerNode<D>(tree, e.node, e.cell, rays, hit, k)) continue;
            }
            // The near child is popped next: start loading the children's pair now.
            __builtin_prefetch(&tree.nodes[node.left()]);
            const int axis = node.axis();
            Entry lo{e.cell, node.left(), uint32_t(k)}, hi{e.cell, node.left() + 1, uint32_t(k)};
            if constexpr (KdTreeChildCellsHook<ElemIsect, KdTree<Elem>>) {
                elem.childCells(tree, e.node, e.cell, lo.cell, hi.cell);
            } else {
                lo.cell.hi[axis] = node.split;
                hi.cell.lo[axis] = node.split;
            }
            // Unreachable with the builder's depth limit; release builds drop the subtree.
            RTFACT_ASSERT(sp + 2 <= kStackSize, "kd-tree deeper than the traversal stack");
            if (sp + 2 > kStackSize) continue;
            if (rays.dir[axis][k * W] < 0.0f) {
                new (&stack[sp++]) Entry(lo);
                new (&stack[sp++]) Entry(hi);
            } else {
                new (&stack[sp++]) Entry(hi);
                new (&stack[sp++]) Entry(lo);
            }
        }
    }
};

}  // namespace rtfact
