// KdTree<Elem>: a kd-tree over any elements with bounds. Nodes are 8 bytes; children of
// an inner node are adjacent; a leaf lists element indices (an element may sit in
// several leaves).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "core/concepts/builder.h"
#include "core/concepts/primitive.h"

namespace rtfact {

struct KdNode {
    uint32_t word;  // low 2 bits: split axis, 3 = leaf; upper 30 bits: left child / first index
    union {
        float split;
        uint32_t count;
    };

    bool isLeaf() const { return (word & 3u) == 3u; }
    int axis() const { return int(word & 3u); }
    uint32_t left() const { return word >> 2; }
    uint32_t first() const { return word >> 2; }
    static KdNode leaf(uint32_t first, uint32_t count) {
        KdNode n;
        n.word = (first << 2) | 3u;
        n.count = count;
        return n;
    }
    static KdNode inner(int axis, float split, uint32_t left) {
        KdNode n;
        n.word = (left << 2) | uint32_t(axis);
        n.split = split;
        return n;
    }
};
static_assert(sizeof(KdNode) == 8);

struct KdTopology {
    std::vector<KdNode> nodes;
    std::vector<uint32_t> indices;  // leaf element lists: input element indices
    AABB box;                       // bounds of the whole tree

    bool empty() const { return nodes.empty(); }
};

template <class Elem>
struct KdTree : KdTopology {
    using Element = Elem;
    std::vector<Elem> elems;  // in input order; indices refer to them

    size_t memoryBytes() const {
        return nodes.size() * sizeof(KdNode) + indices.size() * sizeof(uint32_t) + elems.size() * sizeof(Elem);
    }
};

template <Primitive Elem, class B>
requires Builder<B, KdTopology> KdTree<Elem> buildKdTree(const B& builder, std::span<const Elem> elems) {
    std::vector<AABB> bounds(elems.size());
    for (size_t i = 0; i < elems.size(); ++i) bounds[i] = elems[i].bounds();
    KdTree<Elem> tree;
    builder.build(std::span<const AABB>(bounds), static_cast<KdTopology&>(tree));
    tree.elems.assign(elems.begin(), elems.end());
    return tree;
}

}  // namespace rtfact
