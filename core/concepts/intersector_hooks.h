// Optional hooks an element intersector may offer to a traversal. Each is a named
// concept, used by the traversal's `if constexpr` and asserted next to every model, so
// a renamed hook or a drifted signature stops the build instead of silently falling
// back to the plain path (no LoD cut, no SIMD leaf test).
#pragma once
#include <concepts>
#include <cstdint>

#include "core/concepts/intersector.h"
#include "core/math/aabb.h"

namespace rtfact {

// Kd-tree traversal: answer an inner node of `Tree` itself (level-of-detail cuts);
// returns true when the node's subtree need not be visited.
template <class I, class Tree, int N>
concept KdTreeInnerNodeHook = requires(const I& isect, const Tree& tree, uint32_t node, const AABB& cell,
                                       const RayPacket<N>& rays, typename I::template Hit<N>& hit) {
    { isect.template innerNode<HitData::Distance>(tree, node, cell, rays, hit, 0) } -> std::same_as<bool>;
    { isect.template innerNode<HitData::Shading>(tree, node, cell, rays, hit, 0) } -> std::same_as<bool>;
};

// Kd-tree traversal: the children's cells of an inner node, for elements that reach
// beyond the split plane (discs stored once, by centre).
template <class I, class Tree>
concept KdTreeChildCellsHook = requires(const I& isect, const Tree& tree, uint32_t node, const AABB& cell, AABB& lo,
                                        AABB& hi) {
    isect.childCells(tree, node, cell, lo, hi);
};

// Wide BVH single-ray traversal: a whole leaf of `count` elements against one ray at
// once (SIMD over elements).
template <class I, class E>
concept LeafIntersector = requires(const I& isect, const E* elems, const uint32_t* ids, int count,
                                   const RayPacket<1>& ray, typename I::template Hit<1>& hit) {
    isect.template intersectLeaf<HitData::Distance>(elems, ids, count, ray, hit);
    isect.template intersectLeaf<HitData::Shading>(elems, ids, count, ray, hit);
};

}  // namespace rtfact
