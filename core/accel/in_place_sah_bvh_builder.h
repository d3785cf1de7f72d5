// Binned SAH BVH builder on primitive references that are partitioned in place (no
// indirection through an order array while building; blockPartition, which also gives
// both halves' bounds and centroid bounds), so every level costs one binning and one
// partition over contiguous memory. Subtrees are built in parallel with TBB. Works on
// bounds only, like every builder.
#pragma once
#include <immintrin.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

#include "core/accel/block_partition.h"
#include "core/accel/box4.h"
#include "core/accel/bvh.h"
#include "core/simd/native.h"
#include "core/util/huge_pages.h"

namespace rtfact {

struct InPlaceSAHBVHBuilder {
    int maxLeafSize = 4;  // larger ranges are always split
    float traversalCost = 1.0f;
    float intersectionCost = 1.0f;
    static constexpr int kBins = 16;
    static constexpr int kMaxDepth = 64;
    static constexpr uint32_t kParallelThreshold = 2048;

   private:
    // Reference layout: two 16-byte halves so bounds update with one SSE min/max each;
    // the id rides in the unused fourth lane of lo.
    struct alignas(16) Ref {
        float lo[4];
        float hi[4];
    };
    struct Ctx {
        Ref* refs;
        BVHNode* nodes;
        std::atomic<uint32_t>& next;
    };
    // A bin's bounds, without Box4's initialisers (those would set up all kBins bins of
    // every node; only the ones in use are).
    struct Bin {
        __m128 lo, hi;
    };
    static RTFACT_INLINE __m128 lo4(const Ref& r) { return _mm_load_ps(r.lo); }
    static RTFACT_INLINE __m128 hi4(const Ref& r) { return _mm_load_ps(r.hi); }

   public:
    void build(std::span<const AABB> bounds, BVHTopology& out) const {
        const uint32_t n = uint32_t(bounds.size());
        out.nodes.clear();
        if (n == 0) {
            out.order.clear();
            return;
        }
        std::vector<Ref> refs;
        resizeHugePages(refs, n);
        Box4 box, cbox;
        for (uint32_t i = 0; i < n; ++i) {
            Ref& r = refs[i];
            r = {{bounds[i].lo.x, bounds[i].lo.y, bounds[i].lo.z, 0.0f},
                 {bounds[i].hi.x, bounds[i].hi.y, bounds[i].hi.z, 0.0f}};
            std::memcpy(&r.lo[3], &i, 4);
            extendWithCentroid(box, cbox, lo4(r), hi4(r));
        }
        std::vector<BVHNode> nodes;
        resizeHugePages(nodes, 2 * size_t(n));
        std::atomic<uint32_t> next{1};
        Ctx ctx{refs.data(), nodes.data(), next};
        buildNode(ctx, 0, 0, n, box, cbox, 0);
        out.order.clear();
        resizeHugePages(out.order, n);
        for (uint32_t i = 0; i < n; ++i) std::memcpy(&out.order[i], &refs[i].lo[3], 4);
        // Depth-first order (left child right after its parent's pair) for locality.
        resizeHugePages(out.nodes, next.load());
        out.nodes[0] = nodes[0];
        uint32_t used = 1;
        std::vector<std::pair<uint32_t, uint32_t>> stack;  // (new index, old left child)
        if (!nodes[0].isLeaf()) stack.push_back({0u, uint32_t(nodes[0].ofs)});
        while (!stack.empty()) {
            const auto [parent, oldLeft] = stack.back();
            stack.pop_back();
            const uint32_t newLeft = used;
            used += 2;
            out.nodes[parent].ofs = int32_t(newLeft);
            out.nodes[newLeft] = nodes[oldLeft];
            out.nodes[newLeft + 1] = nodes[oldLeft + 1];
            if (!nodes[oldLeft + 1].isLeaf()) stack.push_back({newLeft + 1, uint32_t(nodes[oldLeft + 1].ofs)});
            if (!nodes[oldLeft].isLeaf()) stack.push_back({newLeft, uint32_t(nodes[oldLeft].ofs)});
        }
    }

   private:
    void makeLeaf(Ctx& ctx, uint32_t ni, uint32_t b, uint32_t e, const Box4& box) const {
        const AABB a = box.aabb();
        ctx.nodes[ni] = {a.lo, int32_t(b), a.hi, int32_t(e - b)};
    }

    void buildNode(Ctx& ctx, uint32_t ni, uint32_t b, uint32_t e, const Box4& box, const Box4& cbox, int depth) const {
        const uint32_t n = e - b;
        if (n <= 1 || depth >= kMaxDepth) return makeLeaf(ctx, ni, b, e, box);
        const AABB cb = cbox.aabb();
        const Vec3f ext = cb.extent();
        int axis = -1, split = 0;
        float bestCost = kInfinityF;
        alignas(16) float scale[4] = {0, 0, 0, 0};
        const __m128 cmin = _mm_setr_ps(cb.lo.x, cb.lo.y, cb.lo.z, 0.0f);
        // Fewer bins for small ranges: setting up and sweeping all of them cost more than
        // binning the few references (most nodes are small).
        const int nb = std::min(kBins, 4 + int(n / 8));
        if (maxComponent(ext) > 0.0f) {
            for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0.0f ? float(nb) * 0.99999f / ext[a] : 0.0f;
            const __m128 sc = _mm_load_ps(scale);
            const __m128i maxBin = _mm_set1_epi32(nb - 1);
            Bin bins[3][kBins];  // only nb per axis set up
            uint32_t counts[3][kBins];
            const Box4 empty;
            for (int a = 0; a < 3; ++a)
                for (int k = 0; k < nb; ++k) bins[a][k] = {empty.lo, empty.hi}, counts[a][k] = 0;
            for (uint32_t i = b; i < e; ++i) {
                const Ref& r = ctx.refs[i];
                const __m128 l = lo4(r), h = hi4(r);
                const __m128i k =
                    _mm_min_epi32(_mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(doubledCentroid(l, h), cmin), sc)), maxBin);
                alignas(16) int32_t ki[4];
                _mm_store_si128(reinterpret_cast<__m128i*>(ki), k);
                for (int a = 0; a < 3; ++a) {
                    counts[a][ki[a]]++;
                    Bin& bin = bins[a][ki[a]];
                    bin.lo = _mm_min_ps(bin.lo, l);
                    bin.hi = _mm_max_ps(bin.hi, h);
                }
            }
            // Sweep: right-to-left areas, then left-to-right costs.
            for (int a = 0; a < 3; ++a) {
                if (ext[a] <= 0.0f) continue;
                float rightArea[kBins];
                uint32_t rightCount[kBins];
                Box4 acc;
                uint32_t cnt = 0;
                for (int k = nb - 1; k > 0; --k) {
                    acc.extend(bins[a][k].lo, bins[a][k].hi);
                    cnt += counts[a][k];
                    rightArea[k] = acc.area();
                    rightCount[k] = cnt;
                }
                acc = Box4{};
                cnt = 0;
                for (int k = 0; k < nb - 1; ++k) {
                    acc.extend(bins[a][k].lo, bins[a][k].hi);
                    cnt += counts[a][k];
                    if (cnt == 0 || rightCount[k + 1] == 0) continue;
                    const float cost = acc.area() * float(cnt) + rightArea[k + 1] * float(rightCount[k + 1]);
                    if (cost < bestCost) {
                        bestCost = cost;
                        axis = a;
                        split = k;
                    }
                }
            }
        }
        const float area = std::max(box.area(), 1e-30f);
        const float splitCost = traversalCost + intersectionCost * bestCost / area;
        if (n <= uint32_t(maxLeafSize) && (axis < 0 || splitCost >= intersectionCost * float(n)))
            return makeLeaf(ctx, ni, b, e, box);

        // Partition in place (no branch per reference), with both halves' bounds.
        Box4 lbox, lcbox, rbox, rcbox;
        uint32_t mid;
        if (axis >= 0) {
            const float s = scale[axis], lo = cb.lo[axis];
            auto left = [&](const Ref& r) {
                return std::min(int((r.lo[axis] + r.hi[axis] - lo) * s), nb - 1) <= split;
            };
            mid = blockPartition(ctx.refs, b, e, left, lbox, lcbox, rbox, rcbox);
        } else {
            // All centroids coincide: split the range in the middle.
            mid = b + n / 2;
            for (uint32_t i = b; i < e; ++i) {
                const Ref& r = ctx.refs[i];
                if (i < mid)
                    extendWithCentroid(lbox, lcbox, lo4(r), hi4(r));
                else
                    extendWithCentroid(rbox, rcbox, lo4(r), hi4(r));
            }
        }
        const uint32_t left = ctx.next.fetch_add(2);
        const AABB a = box.aabb();
        ctx.nodes[ni] = {a.lo, int32_t(left), a.hi, -(axis >= 0 ? axis : 0)};
        auto buildLeft = [&] { buildNode(ctx, left, b, mid, lbox, lcbox, depth + 1); };
        auto buildRight = [&] { buildNode(ctx, left + 1, mid, e, rbox, rcbox, depth + 1); };
        if (n >= kParallelThreshold)
            tbb::parallel_invoke(buildLeft, buildRight);
        else {
            buildLeft();
            buildRight();
        }
    }

    static constexpr float kInfinityF = std::numeric_limits<float>::infinity();
};
static_assert(Builder<InPlaceSAHBVHBuilder, BVHTopology>);

}  // namespace rtfact
