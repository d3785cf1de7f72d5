// Binned SAH BVH builder (works on bounds only). Large ranges are binned and split in
// parallel with TBB; node pairs are allocated atomically and reordered depth first.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <span>
#include <vector>

#include "core/accel/bvh.h"

namespace rtfact {

struct SAHBVHBuilder {
    int maxLeafSize = 8;
    float traversalCost = 1.0f;
    float intersectionCost = 1.0f;
    static constexpr int kBins = 32;
    static constexpr int kMaxDepth = 64;

    void build(std::span<const AABB> bounds, BVHTopology& out) const {
        const uint32_t n = uint32_t(bounds.size());
        out.nodes.clear();
        out.order.resize(n);
        if (n == 0) return;
        std::vector<Vec3f> centroids(n);
        for (uint32_t i = 0; i < n; ++i) {
            out.order[i] = i;
            centroids[i] = bounds[i].center();
        }
        out.nodes.resize(2 * size_t(n));
        Ctx ctx{bounds, centroids, out.order, out.nodes, {1}};
        Range root = rangeBounds(ctx, 0, n);
        buildNode(ctx, 0, root, 0);
        out.nodes.resize(ctx.nextNode.load());
        reorderDepthFirst(out.nodes);
    }

   private:
    struct Ctx {
        std::span<const AABB> bounds;
        std::vector<Vec3f>& centroids;
        std::vector<uint32_t>& order;
        std::vector<BVHNode>& nodes;
        std::atomic<uint32_t> nextNode;
    };
    struct Range {
        uint32_t begin, end;
        AABB box, cbox;  // bounds of the elements and of their centroids
    };
    struct Bins {
        AABB box[3][kBins];
        uint32_t count[3][kBins] = {};
    };

    static Range rangeBounds(Ctx& ctx, uint32_t b, uint32_t e) {
        auto body = [&](const tbb::blocked_range<uint32_t>& r, std::pair<AABB, AABB> acc) {
            for (uint32_t i = r.begin(); i != r.end(); ++i) {
                acc.first.extend(ctx.bounds[ctx.order[i]]);
                acc.second.extend(ctx.centroids[ctx.order[i]]);
            }
            return acc;
        };
        auto join = [](std::pair<AABB, AABB> a, const std::pair<AABB, AABB>& b) {
            return std::pair{merge(a.first, b.first), merge(a.second, b.second)};
        };
        auto r = tbb::parallel_reduce(tbb::blocked_range<uint32_t>(b, e, 16384), std::pair<AABB, AABB>{}, body, join);
        return {b, e, r.first, r.second};
    }

    void binRange(Ctx& ctx, const Range& r, Bins& bins, const Vec3f& scale) const {
        for (uint32_t i = r.begin; i < r.end; ++i) {
            const uint32_t id = ctx.order[i];
            const Vec3f c = ctx.centroids[id];
            for (int a = 0; a < 3; ++a) {
                int b = int((c[a] - r.cbox.lo[a]) * scale[a]);
                b = std::clamp(b, 0, kBins - 1);
                bins.count[a][b]++;
                bins.box[a][b].extend(ctx.bounds[id]);
            }
        }
    }

    void makeLeaf(Ctx& ctx, uint32_t ni, const Range& r) const {
        BVHNode& n = ctx.nodes[ni];
        n.lo = r.box.lo;
        n.hi = r.box.hi;
        n.ofs = int32_t(r.begin);
        n.meta = int32_t(r.end - r.begin);
    }

    void buildNode(Ctx& ctx, uint32_t ni, const Range& r, int depth) const {
        const uint32_t n = r.end - r.begin;
        if (n <= 1 || depth >= kMaxDepth) return makeLeaf(ctx, ni, r);
        const Vec3f ext = r.cbox.extent();
        int bestAxis = -1, bestBin = -1;
        float bestCost = intersectionCost * float(n);
        uint32_t mid = r.begin;
        if (maxComponent(ext) > 0.0f) {
            Vec3f scale;
            for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0 ? float(kBins) * 0.9999f / ext[a] : 0.0f;
            Bins bins;
            if (n >= 65536) {
                bins = tbb::parallel_reduce(
                    tbb::blocked_range<uint32_t>(r.begin, r.end, 16384), Bins{},
                    [&](const tbb::blocked_range<uint32_t>& br, Bins acc) {
                        binRange(ctx, Range{br.begin(), br.end(), r.box, r.cbox}, acc, scale);
                        return acc;
                    },
                    [](Bins a, const Bins& b) {
                        for (int ax = 0; ax < 3; ++ax)
                            for (int i = 0; i < kBins; ++i) {
                                a.count[ax][i] += b.count[ax][i];
                                a.box[ax][i].extend(b.box[ax][i]);
                            }
                        return a;
                    });
            } else {
                binRange(ctx, r, bins, scale);
            }
            const float invArea = 1.0f / std::max(r.box.surfaceArea(), 1e-30f);
            for (int a = 0; a < 3; ++a) {
                if (ext[a] <= 0.0f) continue;
                float rightArea[kBins];
                uint32_t rightCount[kBins];
                AABB acc;
                uint32_t cnt = 0;
                for (int i = kBins - 1; i > 0; --i) {
                    acc.extend(bins.box[a][i]);
                    cnt += bins.count[a][i];
                    rightArea[i] = acc.surfaceArea();
                    rightCount[i] = cnt;
                }
                acc = AABB{};
                cnt = 0;
                for (int i = 0; i < kBins - 1; ++i) {
                    acc.extend(bins.box[a][i]);
                    cnt += bins.count[a][i];
                    if (cnt == 0 || rightCount[i + 1] == 0) continue;
                    const float cost = traversalCost + intersectionCost * invArea *
                                                           (acc.surfaceArea() * float(cnt) +
                                                            rightArea[i + 1] * float(rightCount[i + 1]));
                    if (cost < bestCost) {
                        bestCost = cost;
                        bestAxis = a;
                        bestBin = i;
                    }
                }
            }
            if (bestAxis >= 0) {
                const float s = scale[bestAxis], lo = r.cbox.lo[bestAxis];
                auto it = std::partition(ctx.order.begin() + r.begin, ctx.order.begin() + r.end, [&](uint32_t id) {
                    const int b = std::clamp(int((ctx.centroids[id][bestAxis] - lo) * s), 0, kBins - 1);
                    return b <= bestBin;
                });
                mid = uint32_t(it - ctx.order.begin());
            }
        }
        if (bestAxis < 0) {
            // No split beats a leaf: keep it unless it is too big, then split the
            // centroid-sorted range in the middle.
            if (n <= uint32_t(maxLeafSize)) return makeLeaf(ctx, ni, r);
            bestAxis = r.cbox.maxAxis();
            mid = r.begin + n / 2;
            std::nth_element(
                ctx.order.begin() + r.begin, ctx.order.begin() + mid, ctx.order.begin() + r.end,
                [&](uint32_t x, uint32_t y) { return ctx.centroids[x][bestAxis] < ctx.centroids[y][bestAxis]; });
        }
        const uint32_t left = ctx.nextNode.fetch_add(2);
        BVHNode& node = ctx.nodes[ni];
        node.lo = r.box.lo;
        node.hi = r.box.hi;
        node.ofs = int32_t(left);
        node.meta = -bestAxis;
        auto buildLeft = [&] { buildNode(ctx, left, rangeBounds(ctx, r.begin, mid), depth + 1); };
        auto buildRight = [&] { buildNode(ctx, left + 1, rangeBounds(ctx, mid, r.end), depth + 1); };
        if (n >= 4096)
            tbb::parallel_invoke(buildLeft, buildRight);
        else {
            buildLeft();
            buildRight();
        }
    }
};
static_assert(Builder<SAHBVHBuilder, BVHTopology>);

}  // namespace rtfact
