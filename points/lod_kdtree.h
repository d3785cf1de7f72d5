// LoDKdTree: a kd-tree over discs stored once each, in leaf order (no index list),
// whose every node also carries a representative disc summarising its subtree
// (area-weighted centre, normal and colour; radius covering the subtree). Because a disc
// may reach across its node's split plane, each inner node also keeps the extent of
// its two children along the split axis (a bounding-interval pair), which the
// traversal uses to clip the children's cells.
#pragma once
#include <array>
#include <vector>

#include "core/accel/kdtree.h"
#include "points/disc.h"

namespace rtfact::points {

struct LoDKdTree : KdTree<Disc> {
    std::vector<Disc> reps;                    // one per node (leaves included)
    std::vector<std::array<float, 2>> planes;  // per inner node, at (left child - 1) / 2: {left hi, right lo}

    size_t memoryBytes() const {
        return KdTree<Disc>::memoryBytes() + reps.size() * sizeof(Disc) + planes.size() * sizeof(planes[0]);
    }
    double bytesPerPoint() const { return elems.empty() ? 0.0 : double(memoryBytes()) / double(elems.size()); }
};

// Median split of the longest axis of the centres' cell, subtrees built in parallel
// (TBB); node slots are computed up front so that threads write disjoint ranges.
struct LoDKdTreeBuilder {
    int maxLeafSize = 8;
    LoDKdTree build(std::vector<Disc> discs) const;
};

}  // namespace rtfact::points
