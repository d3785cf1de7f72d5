// BVH<Elem>: a binary bounding volume hierarchy over any elements with bounds.
// Nodes are 32 bytes, children of an inner node are adjacent, elements are stored in
// leaf order so a leaf is a contiguous range.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "core/concepts/builder.h"
#include "core/concepts/primitive.h"

namespace rtfact {

struct BVHNode {
    Vec3f lo;
    int32_t ofs;  // inner: index of the left child (right = ofs + 1); leaf: first element
    Vec3f hi;
    int32_t meta;  // leaf: element count (> 0); inner: -split axis (0, -1, -2)

    bool isLeaf() const { return meta > 0; }
    int count() const { return meta; }
    int axis() const { return -meta; }
    AABB box() const { return {lo, hi}; }
};
static_assert(sizeof(BVHNode) == 32);

// What a BVH builder produces: nodes (root at 0, depth-first order) and the element
// order of the leaves.
struct BVHTopology {
    std::vector<BVHNode> nodes;
    std::vector<uint32_t> order;  // order[i] = input index of the i-th element in leaf order

    AABB bounds() const { return nodes.empty() ? AABB{} : nodes[0].box(); }
    bool empty() const { return order.empty(); }
};

template <class Elem>
struct BVH : BVHTopology {
    using Element = Elem;
    std::vector<Elem> elems;  // in leaf order; elems[i] came from input index order[i]

    size_t memoryBytes() const {
        return nodes.size() * sizeof(BVHNode) + elems.size() * sizeof(Elem) + order.size() * sizeof(uint32_t);
    }
};

template <Primitive Elem, class B>
requires Builder<B, BVHTopology> BVH<Elem> buildBVH(const B& builder, std::span<const Elem> elems) {
    std::vector<AABB> bounds(elems.size());
    for (size_t i = 0; i < elems.size(); ++i) bounds[i] = elems[i].bounds();
    BVH<Elem> bvh;
    builder.build(std::span<const AABB>(bounds), static_cast<BVHTopology&>(bvh));
    bvh.elems.resize(bvh.order.size());
    for (size_t i = 0; i < bvh.order.size(); ++i) bvh.elems[i] = elems[bvh.order[i]];
    return bvh;
}

// Reorders nodes depth first (left child right after its parent's pair) for locality.
inline void reorderDepthFirst(std::vector<BVHNode>& nodes) {
    if (nodes.empty()) return;
    std::vector<BVHNode> out;
    out.reserve(nodes.size());
    out.push_back(nodes[0]);
    // (new index of the node whose children are to be placed, old left child)
    std::vector<std::pair<uint32_t, uint32_t>> stack;
    if (!nodes[0].isLeaf()) stack.push_back({0u, uint32_t(nodes[0].ofs)});
    while (!stack.empty()) {
        auto [parent, oldLeft] = stack.back();
        stack.pop_back();
        const uint32_t newLeft = uint32_t(out.size());
        out[parent].ofs = int32_t(newLeft);
        out.push_back(nodes[oldLeft]);
        out.push_back(nodes[oldLeft + 1]);
        if (!nodes[oldLeft + 1].isLeaf()) stack.push_back({newLeft + 1, uint32_t(nodes[oldLeft + 1].ofs)});
        if (!nodes[oldLeft].isLeaf()) stack.push_back({newLeft, uint32_t(nodes[oldLeft].ofs)});
    }
    nodes.swap(out);
}

// SAH cost of a BVH (traversal cost per inner node, intersection cost per element),
// relative to the root's surface area.
inline float sahCost(const BVHTopology& t, float ct = 1.0f, float ci = 1.0f) {
    if (t.nodes.empty()) return 0.0f;
    const float rootArea = t.nodes[0].box().surfaceArea();
    if (rootArea <= 0.0f) return 0.0f;
    double cost = 0;
    for (const BVHNode& n : t.nodes) cost += double(n.box().surfaceArea()) * (n.isLeaf() ? ci * n.count() : ct);
    return float(cost / rootArea);
}

}  // namespace rtfact
