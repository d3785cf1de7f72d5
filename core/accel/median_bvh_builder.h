// Object-median BVH builder: splits the centroid-sorted elements in half along the
// widest axis. The reference that SAH builds must beat, and a fast builder for
// uniformly distributed elements.
#pragma once
#include <algorithm>
#include <span>
#include <vector>

#include "core/accel/bvh.h"

namespace rtfact {

struct MedianBVHBuilder {
    int maxLeafSize = 4;

    void build(std::span<const AABB> bounds, BVHTopology& out) const {
        const uint32_t n = uint32_t(bounds.size());
        out.nodes.clear();
        out.order.resize(n);
        if (n == 0) return;
        for (uint32_t i = 0; i < n; ++i) out.order[i] = i;
        out.nodes.reserve(2 * size_t(n));
        out.nodes.emplace_back();
        buildNode(bounds, out, 0, 0, n);
    }

   private:
    void buildNode(std::span<const AABB> bounds, BVHTopology& out, uint32_t ni, uint32_t b, uint32_t e) const {
        AABB box, cbox;
        for (uint32_t i = b; i < e; ++i) {
            box.extend(bounds[out.order[i]]);
            cbox.extend(bounds[out.order[i]].center());
        }
        out.nodes[ni].lo = box.lo;
        out.nodes[ni].hi = box.hi;
        if (e - b <= uint32_t(maxLeafSize)) {
            out.nodes[ni].ofs = int32_t(b);
            out.nodes[ni].meta = int32_t(e - b);
            return;
        }
        const int axis = cbox.maxAxis();
        const uint32_t mid = b + (e - b) / 2;
        std::nth_element(out.order.begin() + b, out.order.begin() + mid, out.order.begin() + e,
                         [&](uint32_t x, uint32_t y) { return bounds[x].center()[axis] < bounds[y].center()[axis]; });
        const uint32_t left = uint32_t(out.nodes.size());
        out.nodes.emplace_back();
        out.nodes.emplace_back();
        out.nodes[ni].ofs = int32_t(left);
        out.nodes[ni].meta = -axis;
        buildNode(bounds, out, left, b, mid);
        buildNode(bounds, out, left + 1, mid, e);
    }
};
static_assert(Builder<MedianBVHBuilder, BVHTopology>);

}  // namespace rtfact
