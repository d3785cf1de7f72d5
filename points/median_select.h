// selectByCoordinate: nth_element of discs by one centre coordinate, branch-free for
// large ranges (the LoD builders' median splits).
#pragma once
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/util/assert.h"
#include "points/disc.h"

namespace rtfact::points {

// Branch-free Lomuto partition: discs whose coordinate is below `pivot` to the front.
// Every step swaps unconditionally (a big disc with itself or with the first big one),
// so there is no data-dependent branch to mispredict; returns the number below.
inline size_t partitionBelow(Disc* d, size_t n, int axis, float pivot) {
    size_t j = 0;
    for (size_t i = 0; i < n; ++i) {
        const Disc x = d[i];
        const bool below = x.center[axis] < pivot;
        d[i] = d[j];
        d[j] = x;
        j += below;
    }
    return j;
}

// partitionBelow on several threads: chunks of `chunk` discs are partitioned on their
// own, then the discs at or above the pivot that lie before the split j trade places with
// those below it that lie after j, paired by rank (the k-th misplaced high one with the
// k-th misplaced low one). The order depends on the chunk size only, not on the threads.
inline size_t partitionBelowParallel(Disc* d, size_t n, int axis, float pivot, size_t chunk = size_t(1) << 16) {
    const size_t chunks = (n + chunk - 1) / chunk;
    std::vector<size_t> below(chunks);
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const size_t b = c * chunk, e = std::min(n, b + chunk);
        below[c] = partitionBelow(d + b, e - b, axis, pivot);
    });
    size_t j = 0;
    for (size_t x : below) j += x;
    // Runs of misplaced discs in position order, and the rank each run starts at.
    struct Run {
        size_t start, len, rank;
    };
    std::vector<Run> highs, lows;
    size_t nh = 0, nl = 0;
    for (size_t c = 0; c < chunks; ++c) {
        const size_t b = c * chunk, e = std::min(n, b + chunk), m = b + below[c];
        if (std::min(e, j) > m) {  // high ones in [m, e) before j
            highs.push_back({m, std::min(e, j) - m, nh});
            nh += highs.back().len;
        }
        if (m > std::max(b, j)) {  // low ones in [b, m) after j
            lows.push_back({std::max(b, j), m - std::max(b, j), nl});
            nl += lows.back().len;
        }
    }
    RTFACT_ASSERT(nh == nl, "partition: misplaced counts differ");
    auto runAt = [](const std::vector<Run>& runs, size_t rank) {
        return std::upper_bound(runs.begin(), runs.end(), rank, [](size_t r, const Run& x) { return r < x.rank; }) - 1;
    };
    tbb::parallel_for(size_t(0), (nh + chunk - 1) / chunk, [&](size_t t) {
        const size_t r0 = t * chunk, r1 = std::min(nh, r0 + chunk);
        auto h = runAt(highs, r0), l = runAt(lows, r0);
        size_t hi = r0 - h->rank, li = r0 - l->rank;
        for (size_t r = r0; r < r1; ++r) {
            if (hi == h->len) ++h, hi = 0;
            if (li == l->len) ++l, li = 0;
            std::swap(d[h->start + hi++], d[l->start + li++]);
        }
    });
    return j;
}

// The float's bits as an int32 ordered like the floats (negative ones flipped): -0 sorts
// before +0 and NaNs at the ends, so every key has a place (float compares would let NaNs
// share a rank).
inline int32_t orderedKey(float f) {
    const int32_t b = std::bit_cast<int32_t>(f);
    return b ^ ((b >> 31) & 0x7fffffff);
}

// Ranks of n <= L keys (key[n..L) = INT32_MAX): the number of keys before each one, ties
// in index order, counted for all L lanes at once per key (no branches: the SIMD compares
// GCC makes of the fixed-length lane loop). Strict comparisons first, one compare and one
// add per lane and key; the ranks sum to n(n-1)/2 exactly when no keys tie, and only
// otherwise are ties counted.
template <int L>
inline void rankKeys(const int32_t* key, int32_t* rank, size_t n) {
    for (int i = 0; i < L; ++i) rank[i] = 0;
    for (int j = 0; j < int(n); ++j) {
        const int32_t kj = key[j];
        for (int i = 0; i < L; ++i) rank[i] += int32_t(kj < key[i]);
    }
    int64_t sum = 0;
    for (int i = 0; i < int(n); ++i) sum += rank[i];
    if (sum == int64_t(n) * int64_t(n - 1) / 2) return;
    for (int j = 0; j < int(n); ++j) {
        const int32_t kj = key[j];
        for (int i = 0; i < L; ++i) rank[i] += int32_t((kj == key[i]) & (j < i));
    }
}

// Sorts n <= L items by their ordered keys (key(i)), placing them by rank: the selection's
// last step on small ranges and its sample sort, where std::nth_element's and std::sort's
// branchy partitions took most of the time (a 64-disc median 3.0 against 8.2 ns a disc, a
// 512-disc one 5.3 against 7.0: the 32M LoD build's ranges below a few thousand discs cost
// more per disc than the large ones).
template <int L, class T, class Key>
inline void rankSort(T* d, size_t n, const Key& key) {
    RTFACT_ASSERT(n <= size_t(L), "rank sort: range larger than its lanes");
    alignas(64) int32_t k[L], rank[L];
    for (int i = 0; i < L; ++i) k[i] = i < int(n) ? key(d[i]) : INT32_MAX;
    rankKeys<L>(k, rank, n);
    T tmp[L];
    for (int i = 0; i < int(n); ++i) tmp[rank[i]] = d[i];
    std::copy(tmp, tmp + n, d);
}

// rankSort with as few lanes (16, 32, ... up to Max) as hold n <= Max items.
template <int Max, int L = 16, class T, class Key>
inline void rankSortFitting(T* d, size_t n, const Key& key) {
    if constexpr (L >= Max)
        rankSort<Max>(d, n, key);
    else if (n <= size_t(L))
        rankSort<L>(d, n, key);
    else
        rankSortFitting<Max, 2 * L>(d, n, key);
}

// Ranges up to this size are rank-sorted instead of partitioned further.
constexpr size_t kRankSortMax = 64;

// Sorts n <= kRankSortMax discs by one centre coordinate (ties in input order).
inline void rankSortByCoordinate(Disc* d, size_t n, int axis) {
    rankSortFitting<int(kRankSortMax)>(d, n, [axis](const Disc& x) { return orderedKey(x.center[axis]); });
}

// Sorts the selection's pivot sample (n <= 255 floats): by rank up to 128.
inline void sortSample(float* f, size_t n) {
    if (n <= 128)
        rankSortFitting<128>(f, n, [](float x) { return orderedKey(x); });
    else
        std::sort(f, f + n);
}

// Ranges from this size on are partitioned on several threads (the root of a LoD build:
// before the first split nothing else can run).
constexpr size_t kParallelPartition = size_t(1) << 20;

// nth_element by coordinate with the postcondition of std::nth_element. Each round sorts
// a stratified sample and takes two pivots about sqrt(samples) sample ranks either side
// of the target's estimated rank (Floyd-Rivest style): one branch-free pass moves what is
// below the low pivot to the front, a second pass over the rest moves what is below the
// high pivot, and the target almost always lies between them, in a range of a few
// percent. About 1.8 partition passes in all against 2.5 for a single pivot placed just
// above the target, and it pays down to small ranges, which std::nth_element's branchy
// partitions made ~70% of the build.
inline void selectByCoordinate(Disc* d, size_t n, size_t k, int axis) {
    auto less = [axis](const Disc& x, const Disc& y) { return x.center[axis] < y.center[axis]; };
    while (n > kRankSortMax) {
        const size_t samples = std::clamp<size_t>(n / 16, 15, 255) | 1;
        float sample[255];
        // Sample s at (2s + 1) n / (2 samples), stepped by quotient and remainder: one
        // division per round instead of one per sample.
        const size_t den = 2 * samples, stepQ = 2 * n / den, stepR = 2 * n % den;
        for (size_t s = 0, q = n / den, r = n % den; s < samples; ++s) {
            sample[s] = d[q].center[axis];
            q += stepQ;
            r += stepR;
            if (r >= den) r -= den, ++q;
        }
        sortSample(sample, samples);
        const size_t t = k * samples / n, delta = size_t(std::sqrt(double(samples)));
        const float lo = sample[t > delta ? t - delta : 0], hi = sample[std::min(samples - 1, t + delta)];
        const size_t j1 =
            n >= kParallelPartition ? partitionBelowParallel(d, n, axis, lo) : partitionBelow(d, n, axis, lo);
        if (k < j1) {
            n = j1;
            continue;
        }
        d += j1;
        k -= j1;
        n -= j1;
        const size_t j2 =
            n >= kParallelPartition ? partitionBelowParallel(d, n, axis, hi) : partitionBelow(d, n, axis, hi);
        if (k < j2) {
            n = j2;
        } else if (j2 > 0) {
            d += j2;
            k -= j2;
            n -= j2;
        } else if (j1 == 0) {
            break;  // nothing below either pivot (ties): let std::nth_element finish
        }
    }
    if (n <= kRankSortMax)
        rankSortByCoordinate(d, n, axis);
    else
        std::nth_element(d, d + k, d + n, less);
}

inline void selectMedianByCoordinate(Disc* d, size_t n, size_t k, int axis) { selectByCoordinate(d, n, k, axis); }

}  // namespace rtfact::points
