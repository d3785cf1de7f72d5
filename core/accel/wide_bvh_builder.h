// WideSAHBVHBuilder: builds a K-wide BVH directly (no binary tree, no collapse pass).
// Each node starts from one binned SAH split of its range and keeps splitting the child
// with the largest surface area until it has K children, as Embree's medium-quality
// builder does. Leaves are costed in whole blocks of `leafBlock` elements (the leaf
// SIMD width: a leaf of 5 costs as much as one of 8 when blocks are 4 wide), a range of
// at most one block is always a leaf, and the range stops being split once the block
// cost of a leaf is no more than the split's. Works on bounds only, like every builder.
//
// Speed: references are 32 bytes (min and max in two SSE halves, the id in the spare
// lane); small ranges use few bins (the bin clear and sweep would dominate), large ones
// alternate between two bin sets. With more than one thread the root node's ranges (and
// below it only ranges too large for the subtree tasks to keep threads busy) bin in
// parallel, one bin set per block of kGrain references, and partition in place in
// parallel (partitionParallel: no second reference buffer, whose first-touch page faults
// cost more than the pass it saved). Every other range is binned and partitioned
// serially in place inside parallel subtree tasks (blockPartition: no branch on a
// reference's side). The id lane never enters arithmetic (doubledCentroid). The
// depth-first reorder of the nodes runs as parallel tasks too (subtree sizes fix every
// position up front). Scratch nodes live on huge pages (page faults cost more than the
// binning on VMs), and the element bounds can come from a function (no bounds array to
// fill and fault in first).
#pragma once
#include <immintrin.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <type_traits>
#include <vector>

#include "core/accel/block_partition.h"
#include "core/accel/box4.h"
#include "core/accel/wide_bvh.h"
#include "core/util/huge_pages.h"

namespace rtfact {

struct WideSAHBVHBuilder {
    int leafBlock = 4;     // leaf SIMD block: ranges of at most this many are leaves
    int maxLeafSize = 16;  // larger ranges are always split
    float traversalCost = 1.0f;
    float intersectionCost = 1.0f;  // per block of leafBlock elements

    static constexpr int kMaxBins = 32;
    static constexpr int kMaxDepth = 48;
    static constexpr uint32_t kParallelSplit = 16384;  // parallel binning and partition above
    static constexpr uint32_t kParallelTasks = 1024;   // subtrees as tasks above
    static constexpr uint32_t kGrain = 4096;
    static constexpr uint32_t kTwoBinSets = 256;     // ranges binned with two private bin sets
    static constexpr uint32_t kParallelPlace = 256;  // subtrees of this many nodes reordered as tasks

    template <int K>
    void build(std::span<const AABB> bounds, WideBVHTopology<K>& out) const;
    // The same from n elements' bounds computed on the fly (boundsOf(i) returns element
    // i's AABB): no bounds array to fill and fault in first.
    template <int K, class BoundsOf>
    requires std::is_invocable_r_v<AABB, const BoundsOf&, uint32_t>
    void build(uint32_t n, const BoundsOf& boundsOf, WideBVHTopology<K>& out) const;

   private:
    struct alignas(16) Ref {
        float lo[4];  // lo[3] holds the element id bits
        float hi[4];
    };
    // Adds a reference to a box and its doubled centroid to a centroid box.
    static RTFACT_INLINE void extend(Box4& box, Box4& cbox, const Ref& r) {
        extendWithCentroid(box, cbox, _mm_load_ps(r.lo), _mm_load_ps(r.hi));
    }
    // A range of references with its bounds and the bounds of its doubled centroids.
    struct Range {
        uint32_t b = 0, e = 0;
        Box4 box, cbox;
        uint32_t size() const { return e - b; }
    };
    struct Split {
        int axis = -1, pos = 0;  // left: bin index <= pos
        float cost = kInf;       // sum over both sides of half area x blocks
        __m128 cmin, scale;
        int bins = 0;
        // Parallel ranges: the references of each kGrain block that go left, from the
        // block's own bins (the partition then needs no counting pass).
        std::vector<uint32_t> blockLeft;
    };
    // Per axis and bin: bounds (lo, hi) and count, flat: axis a's bin k at a * kMaxBins + k
    // (one index addresses a bin's box and its count). Only the first n bins of each axis
    // are set up (small ranges use few bins: clearing all of them would cost more than
    // binning).
    struct Bins {
        struct alignas(32) Box {
            __m128 lo, hi;
        };
        Box box[3 * kMaxBins];
        uint32_t cnt[3 * kMaxBins];
        int n = 0;
        Bins() {}  // NOLINT: unset, no zeroing (a slot that init() sets up later)
        explicit Bins(int nb) { init(nb); }
        void init(int nb) {
            n = nb;
            const __m128 inf = _mm_set1_ps(kInf), ninf = _mm_set1_ps(-kInf);
            for (int a = 0; a < 3; ++a)
                for (int k = 0; k < nb; ++k) {
                    box[a * kMaxBins + k] = {inf, ninf};
                    cnt[a * kMaxBins + k] = 0;
                }
        }
        __m128 lo(int a, int k) const { return box[a * kMaxBins + k].lo; }
        __m128 hi(int a, int k) const { return box[a * kMaxBins + k].hi; }
        uint32_t count(int a, int k) const { return cnt[a * kMaxBins + k]; }
        RTFACT_INLINE void add(int i, __m128 l, __m128 h) {
            box[i].lo = _mm_min_ps(box[i].lo, l);
            box[i].hi = _mm_max_ps(box[i].hi, h);
            cnt[i]++;
        }
        void merge(const Bins& o) {
            for (int a = 0; a < 3; ++a)
                for (int k = a * kMaxBins; k < a * kMaxBins + n; ++k) {
                    box[k].lo = _mm_min_ps(box[k].lo, o.box[k].lo);
                    box[k].hi = _mm_max_ps(box[k].hi, o.box[k].hi);
                    cnt[k] += o.cnt[k];
                }
        }
    };
    // The scratch tree: per node its children's records (only the used slots: wide nodes
    // are far from full, so this touches less fresh memory than whole nodes would).
    struct ScratchKid {
        float lo[3], hi[3];    // the child's box (plain floats: no initialiser runs on allocation)
        int32_t child, count;  // as WideBVHNode's child and count
        AABB box() const { return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
    };
    struct ScratchNode {
        uint32_t first;    // first record in ScratchKid[]
        uint32_t kids;     // records
        uint32_t subtree;  // inner nodes in its subtree, itself included
    };
    struct Ctx {
        Ref* refs;
        uint32_t* order;
        ScratchNode* nodes;
        ScratchKid* kids;
        // Ranges of this size on bin and partition in parallel: while the root node is
        // widened (nothing else runs then), and below it only ranges so large that the
        // subtree tasks alone would leave threads idle (elsewhere the serial in-place
        // pass does the same work with less memory traffic).
        uint32_t parallelSplit;
        uint32_t parallelSplitBelowRoot;
        std::atomic<uint32_t> next{0}, nextKid{0};
    };

    static constexpr float kInf = std::numeric_limits<float>::infinity();

    float blocks(uint32_t n) const { return float((n + uint32_t(leafBlock) - 1) / uint32_t(leafBlock)); }

    static RTFACT_INLINE __m128i binOf(const Ref& r, __m128 cmin, __m128 scale, __m128i maxBin) {
        const __m128 c = doubledCentroid(_mm_load_ps(r.lo), _mm_load_ps(r.hi));
        return _mm_min_epi32(_mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(c, cmin), scale)), maxBin);
    }

    // Bins refs [b, e). Large ranges alternate between bins and a second private set,
    // merged at the end: consecutive references falling into the same bin then do not
    // wait on each other's read-modify-write of that bin.
    static void binRange(const Ref* refs, uint32_t b, uint32_t e, const Split& s, Bins& bins) {
        const __m128i maxBin = _mm_set1_epi32(s.bins - 1);
        const __m128i axisBase = _mm_setr_epi32(0, kMaxBins, 2 * kMaxBins, 0);
        // a reference's three flat bin indices
        auto flat = [&](const Ref& r) __attribute__((always_inline)) {
            return _mm_add_epi32(binOf(r, s.cmin, s.scale, maxBin), axisBase);
        };
        uint32_t i = b;
        if (e - b >= kTwoBinSets) {
            Bins other(s.bins);
            for (; i + 1 < e; i += 2) {
                const Ref& r0 = refs[i];
                const Ref& r1 = refs[i + 1];
                const __m128i k0 = flat(r0), k1 = flat(r1);
                const __m128 l0 = _mm_load_ps(r0.lo), h0 = _mm_load_ps(r0.hi);
                const __m128 l1 = _mm_load_ps(r1.lo), h1 = _mm_load_ps(r1.hi);
                bins.add(_mm_cvtsi128_si32(k0), l0, h0);
                other.add(_mm_cvtsi128_si32(k1), l1, h1);
                bins.add(_mm_extract_epi32(k0, 1), l0, h0);
                other.add(_mm_extract_epi32(k1, 1), l1, h1);
                bins.add(_mm_extract_epi32(k0, 2), l0, h0);
                other.add(_mm_extract_epi32(k1, 2), l1, h1);
            }
            bins.merge(other);
        }
        for (; i < e; ++i) {
            const Ref& r = refs[i];
            const __m128i k = flat(r);
            const __m128 l = _mm_load_ps(r.lo), h = _mm_load_ps(r.hi);
            bins.add(_mm_cvtsi128_si32(k), l, h);
            bins.add(_mm_extract_epi32(k, 1), l, h);
            bins.add(_mm_extract_epi32(k, 2), l, h);
        }
    }

    Split findSplit(const Ctx& ctx, const Range& r, int depth) const {
        const Ref* refs = ctx.refs;
        Split s;
        const uint32_t n = r.size();
        const AABB cb = r.cbox.aabb();
        const Vec3f ext = cb.extent();
        if (!(maxComponent(ext) > 0.0f)) return s;
        s.bins = std::min(kMaxBins, 4 + int(n / 20));
        alignas(16) float sc[4] = {0, 0, 0, 0};
        for (int a = 0; a < 3; ++a) sc[a] = ext[a] > 0.0f ? float(s.bins) * 0.99999f / ext[a] : 0.0f;
        s.scale = _mm_load_ps(sc);
        s.cmin = _mm_setr_ps(cb.lo.x, cb.lo.y, cb.lo.z, 0.0f);
        Bins bins(s.bins);
        // Parallel: bins per kGrain block (kept: their counts place each block's
        // references in the partition), merged in block order.
        std::vector<Bins> blockBins;
        if (n >= (depth == 0 ? ctx.parallelSplit : ctx.parallelSplitBelowRoot)) {
            blockBins.resize((n + kGrain - 1) / kGrain);
            tbb::parallel_for(size_t(0), blockBins.size(), [&](size_t bi) {
                const uint32_t b = r.b + uint32_t(bi) * kGrain;
                blockBins[bi].init(s.bins);
                binRange(refs, b, std::min(r.e, b + kGrain), s, blockBins[bi]);
            });
            for (const Bins& bb : blockBins) bins.merge(bb);
        } else {
            binRange(refs, r.b, r.e, s, bins);
        }
        // Sweep: right-to-left areas, then left-to-right costs, all in whole blocks.
        for (int a = 0; a < 3; ++a) {
            if (!(ext[a] > 0.0f)) continue;
            float rightCost[kMaxBins];
            Box4 acc;
            uint32_t cnt = 0;
            for (int k = s.bins - 1; k > 0; --k) {
                acc.extend(bins.lo(a, k), bins.hi(a, k));
                cnt += bins.count(a, k);
                rightCost[k] = cnt ? acc.halfArea() * blocks(cnt) : -1.0f;
            }
            acc = Box4{};
            cnt = 0;
            for (int k = 0; k < s.bins - 1; ++k) {
                acc.extend(bins.lo(a, k), bins.hi(a, k));
                cnt += bins.count(a, k);
                if (cnt == 0 || rightCost[k + 1] < 0.0f) continue;
                const float cost = acc.halfArea() * blocks(cnt) + rightCost[k + 1];
                if (cost < s.cost) {
                    s.cost = cost;
                    s.axis = a;
                    s.pos = k;
                }
            }
        }
        if (s.axis >= 0 && !blockBins.empty()) {
            s.blockLeft.resize(blockBins.size());
            for (size_t bi = 0; bi < blockBins.size(); ++bi) {
                uint32_t c = 0;
                for (int k = 0; k <= s.pos; ++k) c += blockBins[bi].count(s.axis, k);
                s.blockLeft[bi] = c;
            }
        }
        return s;
    }

    // Splits r into l and rr, in place.
    void partition(Ctx& ctx, const Range& r, const Split& s, Range& l, Range& rr) const {
        Ref* src = ctx.refs;
        l = Range{};
        rr = Range{};
        const uint32_t n = r.size();
        if (s.axis < 0) {
            // No usable split (all centroids coincide): halve the range as it is.
            const uint32_t mid = r.b + n / 2;
            for (uint32_t i = r.b; i < r.e; ++i) {
                Range& d = i < mid ? l : rr;
                extend(d.box, d.cbox, src[i]);
            }
            l.b = r.b, l.e = mid, rr.b = mid, rr.e = r.e;
            return;
        }
        alignas(16) float scl[4], cmn[4];
        _mm_store_ps(scl, s.scale);
        _mm_store_ps(cmn, s.cmin);
        const int a = s.axis, pos = s.pos, maxBin = s.bins - 1;
        const float sc = scl[a], cm = cmn[a];
        auto left = [=](const Ref& x) { return std::min(int((x.lo[a] + x.hi[a] - cm) * sc), maxBin) <= pos; };
        if (s.blockLeft.empty()) {
            const uint32_t mid = blockPartition(src, r.b, r.e, left, l.box, l.cbox, rr.box, rr.cbox);
            l.b = r.b, l.e = mid, rr.b = mid, rr.e = r.e;
            return;
        }
        partitionParallel(ctx, r, s, l, rr);
    }

    // In place in parallel, in two passes over kGrain blocks and no second buffer (its
    // first touch cost more than the pass it saved). Pass 1 marks each reference's side
    // in a bit array and gathers both children's bounds; each block's left count came
    // from its bins (findSplit), so the left child is [b, b + nl). Pass 2 swaps the
    // misplaced pairs: the k-th right reference inside [b, b + nl) with the k-th left one
    // beyond it, each task a chunk of the left part and its matching misplaced lefts.
    void partitionParallel(Ctx& ctx, const Range& r, const Split& s, Range& l, Range& rr) const {
        Ref* src = ctx.refs;
        const uint32_t n = r.size(), nb = uint32_t(s.blockLeft.size());
        uint32_t nl = 0;
        for (uint32_t c : s.blockLeft) nl += c;
        static_assert(kGrain % 64 == 0, "blocks own whole words of the side bits");
        std::vector<uint64_t, UninitAllocator<uint64_t>> side((n + 63) / 64);  // bit set: goes left
        struct alignas(64) BlockBoxes {
            Box4 lbox, lcbox, rbox, rcbox;
        };
        std::vector<BlockBoxes> boxes(nb);
        const int a = s.axis, pos = s.pos;
        const __m128i maxBinV = _mm_set1_epi32(s.bins - 1);
        tbb::parallel_for(uint32_t(0), nb, [&](uint32_t bi) {
            Box4 lb, lc, rb, rc;
            const uint32_t b = bi * kGrain, e = std::min(n, b + kGrain);
            alignas(16) int32_t k[4];
            for (uint32_t w = b; w < e; w += 64) {
                uint64_t bits = 0;
                const uint32_t we = std::min(e, w + 64);
                for (uint32_t i = w; i < we; ++i) {
                    const Ref& x = src[r.b + i];
                    // The side from binOf, the very computation that binned it.
                    _mm_store_si128(reinterpret_cast<__m128i*>(k), binOf(x, s.cmin, s.scale, maxBinV));
                    if (k[a] <= pos) {
                        extend(lb, lc, x);
                        bits |= uint64_t(1) << (i - w);
                    } else {
                        extend(rb, rc, x);
                    }
                }
                side[w / 64] = bits;
            }
            boxes[bi] = {lb, lc, rb, rc};
        });
        for (const BlockBoxes& bb : boxes) {
            l.box.extend(bb.lbox);
            l.cbox.extend(bb.lcbox);
            rr.box.extend(bb.rbox);
            rr.cbox.extend(bb.rcbox);
        }
        l.b = r.b, l.e = r.b + nl, rr.b = r.b + nl, rr.e = r.e;
        // Bits equal to `want` in [from, to) (positions relative to r.b).
        auto count = [&](uint32_t from, uint32_t to, bool want) {
            uint32_t c = 0;
            for (uint32_t p = from; p < to;) {
                const uint32_t wi = p / 64, lo = p % 64, hi = std::min<uint32_t>(64, to - wi * 64);
                uint64_t w = want ? side[wi] : ~side[wi];
                w >>= lo;
                if (hi - lo < 64) w &= (uint64_t(1) << (hi - lo)) - 1;
                c += uint32_t(__builtin_popcountll(w));
                p = wi * 64 + hi;
            }
            return c;
        };
        // First position >= p whose bit equals `want` (one exists).
        auto next = [&](uint32_t p, bool want) {
            uint32_t wi = p / 64;
            uint64_t w = (want ? side[wi] : ~side[wi]) & (~uint64_t(0) << (p % 64));
            while (!w) w = want ? side[++wi] : ~side[++wi];
            return wi * 64 + uint32_t(__builtin_ctzll(w));
        };
        const uint32_t nlc = (nl + kGrain - 1) / kGrain, nrc = (n - nl + kGrain - 1) / kGrain;
        std::vector<uint32_t> lpre(nlc + 1, 0), rpre(nrc + 1, 0);
        for (uint32_t c = 0; c < nlc; ++c)
            lpre[c + 1] = lpre[c] + count(c * kGrain, std::min(nl, (c + 1) * kGrain), false);
        for (uint32_t c = 0; c < nrc; ++c)
            rpre[c + 1] = rpre[c] + count(nl + c * kGrain, std::min(n, nl + (c + 1) * kGrain), true);
        tbb::parallel_for(uint32_t(0), nlc, [&](uint32_t c) {
            const uint32_t m = lpre[c + 1] - lpre[c];
            if (m == 0) return;
            // The lpre[c]-th misplaced left: its chunk from rpre, then skip within it.
            const uint32_t rc = uint32_t(std::upper_bound(rpre.begin(), rpre.end(), lpre[c]) - rpre.begin()) - 1;
            uint32_t skip = lpre[c] - rpre[rc], j = nl + rc * kGrain;
            uint32_t wi = j / 64;
            uint64_t w = side[wi] & (~uint64_t(0) << (j % 64));
            for (uint32_t pc; (pc = uint32_t(__builtin_popcountll(w))) <= skip;) {
                skip -= pc;
                w = side[++wi];
            }
            for (; skip > 0; --skip) w &= w - 1;
            j = wi * 64 + uint32_t(__builtin_ctzll(w));
            uint32_t i = c * kGrain;
            for (uint32_t k = 0; k < m; ++k) {
                i = next(i, false);
                j = next(j, true);
                std::swap(src[r.b + i], src[r.b + j]);
                ++i, ++j;
            }
        });
    }

    // Returns the child slot (node index, 0) or (first element, count) for range r.
    template <int K>
    std::pair<int32_t, int32_t> buildRange(Ctx& ctx, const Range& r, int depth) const {
        const uint32_t n = r.size();
        auto leaf = [&] {
            const Ref* src = ctx.refs;
            for (uint32_t i = r.b; i < r.e; ++i) std::memcpy(&ctx.order[i], &src[i].lo[3], 4);
            return std::pair<int32_t, int32_t>(int32_t(r.b), int32_t(n));
        };
        if (n <= uint32_t(leafBlock) || depth >= kMaxDepth) return leaf();
        Split s = findSplit(ctx, r, depth);
        const float area = r.box.halfArea();
        if (n <= uint32_t(maxLeafSize) && s.axis >= 0 &&
            intersectionCost * blocks(n) * area <= traversalCost * area + intersectionCost * s.cost)
            return leaf();
        if (s.axis < 0 && n <= uint32_t(maxLeafSize)) return leaf();

        Range kids[K];
        int cnt = 2;
        partition(ctx, r, s, kids[0], kids[1]);
        // Open the largest child until K children (Embree's widening rule).
        while (cnt < K) {
            int best = -1;
            float bestArea = -1.0f;
            for (int i = 0; i < cnt; ++i) {
                if (kids[i].size() <= uint32_t(leafBlock)) continue;
                const float a = kids[i].box.halfArea();
                if (a > bestArea) bestArea = a, best = i;
            }
            if (best < 0) break;
            const Range c = kids[best];
            const Split cs = findSplit(ctx, c, depth);
            partition(ctx, c, cs, kids[best], kids[cnt]);
            ++cnt;
        }
        // Larger children first: any-hit rays meet the big occluders earlier.
        float kidArea[K];
        for (int i = 0; i < cnt; ++i) kidArea[i] = kids[i].box.halfArea();
        for (int i = 1; i < cnt; ++i)
            for (int j = i; j > 0 && kidArea[j - 1] < kidArea[j]; --j) {
                std::swap(kidArea[j - 1], kidArea[j]);
                std::swap(kids[j - 1], kids[j]);
            }
        const uint32_t ni = ctx.next.fetch_add(1, std::memory_order_relaxed);
        std::pair<int32_t, int32_t> slot[K];
        if (n >= kParallelTasks) {
            tbb::task_group g;
            for (int i = 0; i < cnt; ++i) g.run([&, i] { slot[i] = buildRange<K>(ctx, kids[i], depth + 1); });
            g.wait();
        } else {
            for (int i = 0; i < cnt; ++i) slot[i] = buildRange<K>(ctx, kids[i], depth + 1);
        }
        const uint32_t first = ctx.nextKid.fetch_add(uint32_t(cnt), std::memory_order_relaxed);
        uint32_t sub = 1;
        for (int i = 0; i < cnt; ++i) {
            const AABB b = kids[i].box.aabb();
            ctx.kids[first + uint32_t(i)] = {
                {b.lo.x, b.lo.y, b.lo.z}, {b.hi.x, b.hi.y, b.hi.z}, slot[i].first, slot[i].second};
            if (slot[i].second == 0) sub += ctx.nodes[slot[i].first].subtree;
        }
        ctx.nodes[ni] = {first, uint32_t(cnt), sub};
        return {int32_t(ni), 0};
    }

    // Copies the subtree of scratch node oi to out[ni] in depth-first order: a node's
    // inner children next to each other from `free` on, then the first child's subtree,
    // the second's, ... Subtree sizes give every position up front, so large subtrees
    // are placed in parallel.
    template <int K>
    static void place(const ScratchNode* in, const ScratchKid* kids, WideBVHNode<K>* out, uint32_t oi, uint32_t ni,
                      uint32_t free) {
        const ScratchNode& s = in[oi];
        uint32_t inner = 0;
        for (uint32_t i = 0; i < s.kids; ++i) inner += kids[s.first + i].count == 0;
        WideBVHNode<K> d;
        uint32_t kidOld[K], kidNew[K], kidFree[K], m = 0, next = free + inner;
        for (int i = 0; i < K; ++i) {
            if (uint32_t(i) >= s.kids) {
                d.clear(i);
                continue;
            }
            const ScratchKid& k = kids[s.first + uint32_t(i)];
            if (k.count > 0) {
                d.set(i, k.box(), k.child, k.count);
                continue;
            }
            kidOld[m] = uint32_t(k.child);
            kidNew[m] = free + m;
            kidFree[m] = next;
            next += in[kidOld[m]].subtree - 1;
            d.set(i, k.box(), int32_t(kidNew[m]), 0);
            ++m;
        }
        out[ni] = d;
        if (s.subtree >= kParallelPlace) {
            tbb::task_group g;
            for (uint32_t j = 0; j < m; ++j) g.run([=] { place<K>(in, kids, out, kidOld[j], kidNew[j], kidFree[j]); });
            g.wait();
        } else {
            for (uint32_t j = 0; j < m; ++j) place<K>(in, kids, out, kidOld[j], kidNew[j], kidFree[j]);
        }
    }
};

template <int K>
void WideSAHBVHBuilder::build(std::span<const AABB> bounds, WideBVHTopology<K>& out) const {
    build(
        uint32_t(bounds.size()), [&](uint32_t i) { return bounds[i]; }, out);
}

template <int K, class BoundsOf>
requires std::is_invocable_r_v<AABB, const BoundsOf&, uint32_t>
void WideSAHBVHBuilder::build(uint32_t n, const BoundsOf& boundsOf, WideBVHTopology<K>& out) const {
    out.nodes.clear();
    out.order.clear();
    out.box = AABB{};
    if (n == 0) return;
    // The references, first touched by the threads that fill them.
    std::vector<Ref, UninitAllocator<Ref>> refs;
    resizeHugePages(refs, n);
    const bool parallel = tbb::this_task_arena::max_concurrency() > 1;
    resizeHugePages(out.order, n);
    // References and the root's bounds, in parallel.
    struct Boxes {
        Box4 box, cbox;
    };
    const Boxes root = tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(0, n, kGrain), Boxes{},
        [&](const tbb::blocked_range<uint32_t>& br, Boxes acc) {
            for (uint32_t i = br.begin(); i != br.end(); ++i) {
                const AABB b = boundsOf(i);
                Ref& r = refs[i];
                r = {{b.lo.x, b.lo.y, b.lo.z, 0.0f}, {b.hi.x, b.hi.y, b.hi.z, 0.0f}};
                std::memcpy(&r.lo[3], &i, 4);
                extend(acc.box, acc.cbox, r);
            }
            return acc;
        },
        [](Boxes x, const Boxes& y) {
            x.box.extend(y.box);
            x.cbox.extend(y.cbox);
            return x;
        });
    // At most n - 1 inner nodes (each has two or more children) and 2n - 2 children;
    // untouched pages of these upper bounds cost nothing.
    std::vector<ScratchNode, UninitAllocator<ScratchNode>> nodes;
    resizeHugePages(nodes, std::max<uint32_t>(n, 1));
    std::vector<ScratchKid, UninitAllocator<ScratchKid>> kids;
    resizeHugePages(kids, 2 * size_t(std::max<uint32_t>(n, 1)));
    Ctx ctx;
    ctx.refs = refs.data();
    ctx.parallelSplit = parallel ? kParallelSplit : std::numeric_limits<uint32_t>::max();
    ctx.parallelSplitBelowRoot = parallel ? std::max(kParallelSplit, n / 4) : std::numeric_limits<uint32_t>::max();
    ctx.order = out.order.data();
    ctx.nodes = nodes.data();
    ctx.kids = kids.data();
    Range r;
    r.b = 0, r.e = n, r.box = root.box, r.cbox = root.cbox;
    out.box = root.box.aabb();
    const auto top = buildRange<K>(ctx, r, 0);
    if (top.second > 0) {
        // A single leaf: a root with one leaf child.
        resizeHugePages(out.nodes, 1);
        out.nodes[0].set(0, out.box, top.first, top.second);
        for (int i = 1; i < K; ++i) out.nodes[0].clear(i);
        return;
    }
    // Depth-first order (children after their parent) for locality; the root is node 0.
    resizeHugePages(out.nodes, ctx.next.load());
    place<K>(nodes.data(), kids.data(), out.nodes.data(), uint32_t(top.first), 0, 1);
}

static_assert(Builder<WideSAHBVHBuilder, WideBVHTopology<4>>);
static_assert(Builder<WideSAHBVHBuilder, WideBVHTopology<8>>);
static_assert(Builder<WideSAHBVHBuilder, WideBVHTopology<16>>);

}  // namespace rtfact
