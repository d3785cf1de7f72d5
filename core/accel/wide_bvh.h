// WideBVH<Elem, K>: a K-ary BVH (K = 4, 8 or 16), for single-ray traversal that tests
// one ray against all K child boxes with one SIMD op per slab. Nodes are
// structure-of-arrays (K floats per bound and axis); elements are in leaf order, so a
// leaf is a contiguous range. The topology comes either straight from a wide builder
// (core/accel/wide_bvh_builder.h) or from collapsing a binary BVHTopology.
// BlockedWideBVH<Block, K> stores the leaves as SIMD blocks of elements instead
// (structure-of-arrays, one SIMD test per block, no gathers).
#pragma once
#include <tbb/parallel_for.h>

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "core/accel/bvh.h"
#include "core/ray/ray_packet.h"
#include "core/simd/bitmask.h"
#include "core/util/huge_pages.h"

namespace rtfact {

template <int K>
struct alignas(64) WideBVHNode {
    static_assert(K == 4 || K == 8 || K == 16, "wide BVH arity must be 4, 8 or 16");
    float lo[3][K];    // child box minima per axis (empty slots: +inf, never hit)
    float hi[3][K];    // child box maxima per axis (empty slots: -inf)
    int32_t child[K];  // inner child: node index; leaf child: first element
    int32_t count[K];  // leaf child: element count (> 0); inner child or empty slot: 0

    bool isLeaf(int i) const { return count[i] > 0; }
    bool isEmpty(int i) const { return lo[0][i] > hi[0][i]; }
    AABB box(int i) const { return {Vec3f(lo[0][i], lo[1][i], lo[2][i]), Vec3f(hi[0][i], hi[1][i], hi[2][i])}; }
    void set(int i, const AABB& b, int32_t c, int32_t n) {
        for (int a = 0; a < 3; ++a) {
            lo[a][i] = b.lo[a];
            hi[a][i] = b.hi[a];
        }
        child[i] = c;
        count[i] = n;
    }
    void clear(int i) {
        for (int a = 0; a < 3; ++a) {
            lo[a][i] = kInfinity;
            hi[a][i] = -kInfinity;
        }
        child[i] = -1;
        count[i] = 0;
    }
};

// Shape of a wide BVH: nodes (root at 0) and the element order of the leaves. An empty
// tree has no nodes; otherwise the root always exists (a single-leaf tree is a root
// with one leaf child).
template <int K>
struct WideBVHTopology {
    static constexpr int arity = K;
    std::vector<WideBVHNode<K>> nodes;
    std::vector<uint32_t> order;  // order[i] = input index of the i-th element in leaf order
    AABB box;

    AABB bounds() const { return box; }
    bool empty() const { return order.empty(); }
};

// Collapses a binary topology: each wide node starts from the two children of a binary
// inner node and repeatedly opens the inner child with the largest surface area (the one
// most likely to be visited) until it has K children.
template <int K>
WideBVHTopology<K> collapseBVH(const BVHTopology& bin) {
    WideBVHTopology<K> w;
    w.order = bin.order;
    if (bin.nodes.empty() || bin.order.empty()) return w;
    w.box = bin.nodes[0].box();
    w.nodes.reserve(bin.nodes.size() / (K - 1) + 2);
    // (wide node to fill, binary node it stands for)
    std::vector<std::pair<uint32_t, uint32_t>> work;
    w.nodes.emplace_back();
    work.push_back({0u, 0u});
    std::vector<uint32_t> kids;
    kids.reserve(K);
    while (!work.empty()) {
        const auto [wi, bi] = work.back();
        work.pop_back();
        kids.clear();
        const BVHNode& b = bin.nodes[bi];
        if (b.isLeaf()) {
            kids.push_back(bi);
        } else {
            kids.push_back(uint32_t(b.ofs));
            kids.push_back(uint32_t(b.ofs) + 1);
            while (int(kids.size()) < K) {
                int best = -1;
                float bestArea = -1.0f;
                for (int i = 0; i < int(kids.size()); ++i) {
                    const BVHNode& c = bin.nodes[kids[i]];
                    if (c.isLeaf()) continue;
                    const float a = c.box().surfaceArea();
                    if (a > bestArea) bestArea = a, best = i;
                }
                if (best < 0) break;
                const uint32_t open = kids[size_t(best)];
                kids[size_t(best)] = uint32_t(bin.nodes[open].ofs);
                kids.push_back(uint32_t(bin.nodes[open].ofs) + 1);
            }
        }
        for (int i = 0; i < K; ++i) {
            if (i >= int(kids.size())) {
                w.nodes[wi].clear(i);
                continue;
            }
            const BVHNode& c = bin.nodes[kids[size_t(i)]];
            if (c.isLeaf()) {
                w.nodes[wi].set(i, c.box(), c.ofs, c.count());
            } else {
                const uint32_t ni = uint32_t(w.nodes.size());
                w.nodes.emplace_back();  // may reallocate: index, never hold references
                w.nodes[wi].set(i, c.box(), int32_t(ni), 0);
                work.push_back({ni, kids[size_t(i)]});
            }
        }
    }
    return w;
}

template <class Elem, int K = 8>
struct WideBVH : WideBVHTopology<K> {
    using Element = Elem;
    std::vector<Elem> elems;  // in leaf order; elems[i] came from input index order[i]

    size_t memoryBytes() const {
        return this->nodes.size() * sizeof(WideBVHNode<K>) + elems.size() * sizeof(Elem) +
               this->order.size() * sizeof(uint32_t);
    }
};

// A wide BVH from a binary one (same leaves, same element order).
template <int K, class Elem>
WideBVH<Elem, K> collapseBVH(const BVH<Elem>& bvh) {
    WideBVH<Elem, K> w;
    static_cast<WideBVHTopology<K>&>(w) = collapseBVH<K>(static_cast<const BVHTopology&>(bvh));
    w.elems = bvh.elems;
    return w;
}

// Builds a wide BVH over `elems`: directly with a wide builder (WideSAHBVHBuilder), or
// by building the binary BVH with a binary builder and collapsing it.
template <Primitive Elem, int K = 8, class B>
requires(Builder<B, BVHTopology> ||
         Builder<B, WideBVHTopology<K>>) WideBVH<Elem, K> buildWideBVH(const B& builder, std::span<const Elem> elems) {
    if constexpr (Builder<B, WideBVHTopology<K>>) {
        std::vector<AABB> bounds(elems.size());
        for (size_t i = 0; i < elems.size(); ++i) bounds[i] = elems[i].bounds();
        WideBVH<Elem, K> w;
        builder.build(std::span<const AABB>(bounds), static_cast<WideBVHTopology<K>&>(w));
        w.elems.resize(w.order.size());
        for (size_t i = 0; i < w.order.size(); ++i) w.elems[i] = elems[w.order[i]];
        return w;
    } else {
        return collapseBVH<K>(buildBVH<Elem>(builder, elems));
    }
}

// Allocator that leaves new elements uninitialised (large arrays that are filled in
// parallel right after: no serial zeroing pass, first touch by the filling threads).
template <class T>
struct UninitAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = UninitAllocator<U>;
    };
    UninitAllocator() = default;
    template <class U>
    UninitAllocator(const UninitAllocator<U>&) {}  // NOLINT: allocator conversion
    template <class U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... A>
    void construct(U* p, A&&... a) {
        ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
    }
};

// A leaf block: up to kSize elements in structure-of-arrays form, tested against a ray
// with one SIMD op per field. fill(ids, n, get) writes the block from n input indices
// (get(i) returns input element i; unused lanes repeat the last element).
template <class B>
concept LeafBlock = requires {
    { B::kSize } -> std::convertible_to<int>;
    typename B::Element;
};

// A wide BVH whose leaves are blocks: a leaf slot's child is its first block and its
// count the number of elements (ceil(count / kSize) consecutive blocks).
template <LeafBlock Block, int K = 8>
struct BlockedWideBVH : WideBVHTopology<K> {
    using BlockType = Block;
    static constexpr int kBlock = Block::kSize;
    std::vector<Block, UninitAllocator<Block>> blocks;

    static int blockCount(int elements) { return (elements + kBlock - 1) / kBlock; }
    size_t memoryBytes() const {
        return this->nodes.size() * sizeof(WideBVHNode<K>) + blocks.size() * sizeof(Block) +
               this->order.size() * sizeof(uint32_t);
    }
};

// Turns the element-range leaves of a wide topology into blocks, in parallel:
// fill(block, ids, n) writes one block from n <= kSize input indices.
template <LeafBlock Block, int K, class Fill>
BlockedWideBVH<Block, K> packLeafBlocks(WideBVHTopology<K>&& t, const Fill& fill) {
    constexpr int S = Block::kSize;
    BlockedWideBVH<Block, K> out;
    static_cast<WideBVHTopology<K>&>(out) = std::move(t);
    const size_t n = out.order.size(), nn = out.nodes.size();
    if (n == 0) return out;
    // First block of each leaf, by the leaf's first element (leaves tile [0, n)); only
    // leaf starts are written and read (uninitialised: no serial zeroing pass). On huge
    // pages: every 4 KiB page of it is touched.
    std::vector<uint32_t, UninitAllocator<uint32_t>> first;
    resizeHugePages(first, n);
    auto* nodes = out.nodes.data();
    tbb::parallel_for(size_t(0), nn, [&](size_t ni) {
        for (int i = 0; i < K; ++i)
            if (nodes[ni].isLeaf(i)) first[size_t(nodes[ni].child[i])] = uint32_t(nodes[ni].count[i]);
    });
    uint32_t nb = 0;
    for (size_t i = 0; i < n;) {
        const uint32_t c = first[i];
        first[i] = nb;
        nb += uint32_t((c + S - 1) / S);
        i += c;
    }
    resizeHugePages(out.blocks, nb);
    const uint32_t* order = out.order.data();
    Block* blocks = out.blocks.data();
    tbb::parallel_for(size_t(0), nn, [&](size_t ni) {
        for (int i = 0; i < K; ++i) {
            if (!nodes[ni].isLeaf(i)) continue;
            const uint32_t e = uint32_t(nodes[ni].child[i]), c = uint32_t(nodes[ni].count[i]), b = first[e];
            for (uint32_t j = 0; j * S < c; ++j)
                fill(blocks[b + j], order + e + j * S, int(std::min<uint32_t>(S, c - j * S)));
            nodes[ni].child[i] = int32_t(b);
        }
    });
    return out;
}

// Traversal stacks: pushes `e` onto stack[base, sp) kept sorted far to near by `dist`, so
// the nearest entry is popped first (the wide traversals' child order).
template <class Entry>
inline void pushSorted(Entry* stack, int& sp, int base, const Entry& e) {
    int j = sp++;
    while (j > base && stack[j - 1].dist < e.dist) {
        stack[j] = stack[j - 1];
        --j;
    }
    stack[j] = e;
}

// The same order for the children `bits` of one node at once, with distances `dist`:
// each entry (make(c) for child slot c) is stored at its rank, the number of entries
// popped before it (nearer ones, and equally near ones of later slots, as pushSorted
// in slot order leaves them). One K-wide compare per child and no data-dependent
// branch: the insertion's comparisons mispredict on incoherent rays (diffuse bounces
// through the 8-wide BVH: ~5% of their time, AVX2 build, session 42).
template <class Entry, int K, class Make>
RTFACT_INLINE void pushRanked(Entry* stack, int& sp, uint64_t bits, const Packet<K>& dist, Make&& make) {
    const int top = sp + __builtin_popcountll(bits) - 1;
    for (uint64_t r = bits; r; r &= r - 1) {
        const int c = __builtin_ctzll(r);
        const Packet<K> d(dist[c]);
        const uint64_t before = (BitMask<K>(dist < d).w[0] | (BitMask<K>(dist == d).w[0] & (~uint64_t(1) << c))) & bits;
        stack[top - __builtin_popcountll(before)] = make(c);
    }
    sp = top + 1;
}

// Any hit among n leaf blocks (the blocks' occludedBlocks): the first hit lane of the
// first block with one wins and goes into hit (t, id). test(block, t) returns the mask of
// the block's lanes hit in (tMin, hit.t) and sets their distances t.
template <int L, class Block, class H, class Test>
RTFACT_INLINE bool firstBlockHit(const Block* blocks, int n, H& hit, Test&& test) {
    for (int k = 0; k < n; ++k) {
        Packet<L> t;
        const auto m = test(blocks[k], t);
        if (none(m)) continue;
        const int lane = BitMask<L>(m).first();
        hit.t = t[lane];
        hit.id = blocks[k].id[lane];
        return true;
    }
    return false;
}

}  // namespace rtfact
