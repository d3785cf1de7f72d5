// LoDWideBVH: the full-detail wide BVH of disc blocks (points/disc_block.h) with, beside
// every wide node, a representative disc for each of its K children (the child's subtree
// summarised: area-weighted centre, normal and colour; radius covering the subtree). The
// summaries are structure-of-arrays in the parent, so the level-of-detail cut for all K
// children is one SIMD compare on data fetched (and prefetched) with the node, and the
// children cut are tested against the ray with one SIMD disc test: no child fetch and no
// per-level dependent miss below the cut.
#pragma once
#include <span>
#include <vector>

#include "points/disc_block.h"

namespace rtfact::points {

template <int K>
struct alignas(64) LoDChildReps {
    float radius[K];  // covering radius (empty slots: +inf, never cut)
    float c[3][K];    // centre[axis][child]
    float n[3][K];    // unit normal (decoded)
};

// What a representative disc has beyond its centre and radius (kept in LoDChildReps): its
// normal in the discs' octahedral form, for shading exactly as the disc it stands for, and
// its colour with the LoD level in alpha. 8 bytes a child instead of a whole Disc's 24: the
// 32M-point tree's fresh memory, which its first build pays for (docs/benchmarks.md), is
// 68 MB smaller.
struct LoDRepLook {
    uint32_t normal = 0;
    uint32_t rgba = 0;
};

struct LoDWideBVH : DiscWideBVH {
    static constexpr int K = kDiscWideArity;
    static constexpr int kMaxDepth = 48;     // traversal stack; median splits stay below 27 levels
    std::vector<Disc> elems;                 // input discs (median split: in leaf order); block ids index them
    std::vector<LoDChildReps<K>> childReps;  // per node
    std::vector<LoDRepLook> reps;            // [node * K + child]: for shading (normal, colour, level)

    static int32_t repId(int32_t node, int child) { return -(node * K + child) - 2; }
    // The representative disc of slot node * K + child (an empty slot's: radius +inf).
    Disc rep(size_t slot) const {
        const LoDChildReps<K>& cr = childReps[slot / K];
        const size_t c = slot % K;
        Disc d;
        d.center = Vec3f(cr.c[0][c], cr.c[1][c], cr.c[2][c]);
        d.radius = cr.radius[c];
        d.normal = reps[slot].normal;
        d.rgba = reps[slot].rgba;
        return d;
    }
    Disc disc(int32_t id) const { return id >= 0 ? elems[size_t(id)] : rep(size_t(-id - 2)); }
    size_t memoryBytes() const {
        return DiscWideBVH::memoryBytes() + elems.size() * sizeof(Disc) + childReps.size() * sizeof(LoDChildReps<K>) +
               reps.size() * sizeof(LoDRepLook);
    }
};

// How the tree is split. Sah: the core's wide SAH builder (core/accel/wide_bvh_builder.h)
// on the discs' tight bounds, leaves of up to two blocks: the faster tree to trace.
// Median: top-down median splits along the axis the range's centres spread most along
// (points/spread_axis.h; selection, not sorting), up to four levels per wide node, into
// complete subtrees of 8 * 16^j discs and one rest, so that nodes are full (~1 node per 15
// blocks) and every leaf is one full block of discs adjacent in memory, subtrees in
// parallel and depth first: a 5-6x faster build (rtfact-bench points --wide-split compares
// them). Representatives bottom-up either way.
enum class LoDWideSplit { Sah, Median };

LoDWideBVH buildLoDWideBVH(std::vector<Disc> discs, LoDWideSplit split = LoDWideSplit::Sah);

}  // namespace rtfact::points
