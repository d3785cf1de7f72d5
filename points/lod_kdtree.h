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

// What an inner node adds to its 8-byte KdNode: its representative disc and the bounds
// of its two children, quantised to 8 bits per coordinate inside the representative's
// covering sphere box (rounded outwards). The traversal clips the children's cells to
// these boxes, which both tightens them and lets discs reach across split planes.
// Stored at the node's inner ordinal (left child - 1) / 2, so leaves pay nothing.
struct LoDInner {
    Disc rep;
    uint8_t childBox[2][6];  // lo.xyz, hi.xyz per child, in 1/255 of the sphere box
    // Inner index of the right child (the left child's is this one's + 1), so that the
    // traversal can prefetch the far child's summary without waiting for its node.
    uint32_t rightInner = 0;

    AABB box(int child) const {
        const float step = rep.radius * (2.0f / 255.0f);
        const Vec3f base = rep.center - Vec3f(rep.radius);
        const uint8_t* q = childBox[child];
        return {base + Vec3f(float(q[0]), float(q[1]), float(q[2])) * step,
                base + Vec3f(float(q[3]), float(q[4]), float(q[5])) * step};
    }
};
static_assert(sizeof(LoDInner) == 40);

struct LoDKdTree : KdTree<Disc> {
    std::vector<LoDInner> inner;

    static uint32_t innerIndex(const KdNode& n) { return (n.left() - 1) >> 1; }
    const Disc& rep(uint32_t node) const { return inner[innerIndex(nodes[node])].rep; }
    size_t memoryBytes() const { return KdTree<Disc>::memoryBytes() + inner.size() * sizeof(LoDInner); }
    double bytesPerPoint() const { return elems.empty() ? 0.0 : double(memoryBytes()) / double(elems.size()); }
};

// Median split along the axis the centres spread most along (points/spread_axis.h),
// subtrees built in parallel (TBB); node slots are computed up front so that threads write
// disjoint ranges.
struct LoDKdTreeBuilder {
    int maxLeafSize = 8;
    LoDKdTree build(std::vector<Disc> discs) const;
};

}  // namespace rtfact::points
