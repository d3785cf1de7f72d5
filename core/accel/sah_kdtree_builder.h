// SAH kd-tree builder on element bounds: at every node, each axis's candidate planes
// (the element bound faces) are swept in sorted order, O(n log^2 n) overall; the two
// subtrees of large nodes are built in parallel, then flattened depth first.
#pragma once
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include "core/accel/kdtree.h"

namespace rtfact {

struct SAHKdTreeBuilder {
    float traversalCost = 1.0f;
    float intersectionCost = 1.5f;
    float emptyBonus = 0.8f;
    int maxLeafSize = 2;  // below this, stop splitting
    int maxDepth = -1;    // -1: 8 + 1.3 log2(n)

    void build(std::span<const AABB> bounds, KdTopology& out) const {
        out.nodes.clear();
        out.indices.clear();
        out.box = AABB{};
        std::vector<uint32_t> refs;
        refs.reserve(bounds.size());
        for (uint32_t i = 0; i < bounds.size(); ++i) {
            if (bounds[i].isEmpty()) continue;
            out.box.extend(bounds[i]);
            refs.push_back(i);
        }
        if (refs.empty()) {
            out.nodes.push_back(KdNode::leaf(0, 0));
            return;
        }
        const int depth = maxDepth >= 0 ? maxDepth : int(8 + 1.3 * std::log2(double(refs.size())));
        auto root = buildNode(bounds, std::move(refs), out.box, depth);
        out.nodes.push_back({});
        flatten(*root, 0, out);
    }

   private:
    struct Temp {
        int axis = 3;
        float split = 0;
        std::unique_ptr<Temp> child[2];
        std::vector<uint32_t> refs;
    };

    std::unique_ptr<Temp> makeLeaf(std::vector<uint32_t>&& refs) const {
        auto t = std::make_unique<Temp>();
        t->refs = std::move(refs);
        return t;
    }

    std::unique_ptr<Temp> buildNode(std::span<const AABB> bounds, std::vector<uint32_t>&& refs, const AABB& box,
                                    int depth) const {
        const size_t n = refs.size();
        if (n <= size_t(maxLeafSize) || depth <= 0) return makeLeaf(std::move(refs));
        const float invArea = 1.0f / std::max(box.surfaceArea(), 1e-30f);
        const float leafCost = intersectionCost * float(n);
        float bestCost = leafCost;
        int bestAxis = -1;
        float bestSplit = 0;
        std::vector<float> los(n), his(n), flats, planes;
        const Vec3f ext = box.extent();
        for (int a = 0; a < 3; ++a) {
            if (ext[a] <= 0) continue;
            flats.clear();
            for (size_t i = 0; i < n; ++i) {
                los[i] = std::max(bounds[refs[i]].lo[a], box.lo[a]);
                his[i] = std::min(bounds[refs[i]].hi[a], box.hi[a]);
                if (los[i] == his[i]) flats.push_back(los[i]);
            }
            std::sort(los.begin(), los.end());
            std::sort(his.begin(), his.end());
            std::sort(flats.begin(), flats.end());
            planes.assign(los.begin(), los.end());
            planes.insert(planes.end(), his.begin(), his.end());
            std::sort(planes.begin(), planes.end());
            planes.erase(std::unique(planes.begin(), planes.end()), planes.end());
            // Sweep the planes in increasing order. Left of p: elements starting before p
            // and flat ones lying in p; right of p: elements ending after p.
            size_t startsBefore = 0, endsUpTo = 0, flatBefore = 0;
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            for (const float p : planes) {
                while (startsBefore < n && los[startsBefore] < p) ++startsBefore;
                while (endsUpTo < n && his[endsUpTo] <= p) ++endsUpTo;
                while (flatBefore < flats.size() && flats[flatBefore] < p) ++flatBefore;
                if (!(p > box.lo[a] && p < box.hi[a])) continue;
                size_t flatAt = 0;
                while (flatBefore + flatAt < flats.size() && flats[flatBefore + flatAt] == p) ++flatAt;
                const size_t leftCount = startsBefore + flatAt, rightCount = n - endsUpTo;
                const float wl = p - box.lo[a], wr = box.hi[a] - p;
                const float areaL = 2.0f * (ext[b] * ext[c] + wl * (ext[b] + ext[c]));
                const float areaR = 2.0f * (ext[b] * ext[c] + wr * (ext[b] + ext[c]));
                float cost =
                    traversalCost + intersectionCost * invArea * (areaL * float(leftCount) + areaR * float(rightCount));
                if (leftCount == 0 || rightCount == 0) cost *= (1.0f - emptyBonus);
                if (cost < bestCost) {
                    bestCost = cost;
                    bestAxis = a;
                    bestSplit = p;
                }
            }
        }
        if (bestAxis < 0) return makeLeaf(std::move(refs));
        std::vector<uint32_t> left, right;
        left.reserve(n);
        right.reserve(n);
        for (uint32_t r : refs) {
            const float lo = bounds[r].lo[bestAxis], hi = bounds[r].hi[bestAxis];
            if (lo < bestSplit || (lo == bestSplit && hi == bestSplit)) left.push_back(r);
            if (hi > bestSplit) right.push_back(r);
        }
        if (left.size() == n && right.size() == n) return makeLeaf(std::move(refs));
        refs.clear();
        refs.shrink_to_fit();
        AABB lbox = box, rbox = box;
        lbox.hi[bestAxis] = bestSplit;
        rbox.lo[bestAxis] = bestSplit;
        auto t = std::make_unique<Temp>();
        t->axis = bestAxis;
        t->split = bestSplit;
        auto bl = [&] { t->child[0] = buildNode(bounds, std::move(left), lbox, depth - 1); };
        auto br = [&] { t->child[1] = buildNode(bounds, std::move(right), rbox, depth - 1); };
        if (n >= 2048)
            tbb::parallel_invoke(bl, br);
        else {
            bl();
            br();
        }
        return t;
    }

    void flatten(const Temp& t, uint32_t slot, KdTopology& out) const {
        if (t.axis == 3) {
            out.nodes[slot] = KdNode::leaf(uint32_t(out.indices.size()), uint32_t(t.refs.size()));
            out.indices.insert(out.indices.end(), t.refs.begin(), t.refs.end());
            return;
        }
        const uint32_t left = uint32_t(out.nodes.size());
        out.nodes.push_back({});
        out.nodes.push_back({});
        out.nodes[slot] = KdNode::inner(t.axis, t.split, left);
        flatten(*t.child[0], left, out);
        flatten(*t.child[1], left + 1, out);
    }
};
static_assert(Builder<SAHKdTreeBuilder, KdTopology>);

}  // namespace rtfact
