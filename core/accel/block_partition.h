// blockPartition: splits a range of builder references (bounds as two SSE halves, lo
// and hi) in place by a predicate, without a branch on any reference's side, and
// returns the split point with both sides' bounds. A mispredicted branch per reference
// cost the SAH builders more than the rest of the pass (the side of neighbouring
// references is close to random below the top levels). BlockQuicksort's scheme
// (Edelkamp and Weiss 2016): kBlock references from each end are classified into lists
// of the misplaced ones, then misplaced pairs swap; the last few go through a plain
// two-sided pass. Each side's bounds come from one pass over it afterwards (the range
// is in cache by then: cheaper than sorting every box into one of two by its side).
#pragma once
#include <immintrin.h>

#include <algorithm>
#include <cstdint>
#include <utility>

#include "core/accel/box4.h"

namespace rtfact {

// Puts the references of [b, e) for which left(ref) holds first and returns where the
// others start; box / cbox receive the bounds and the doubled-centroid bounds of
// [b, mid) and [mid, e).
template <class Ref, class Left>
uint32_t blockPartition(Ref* src, uint32_t b, uint32_t e, const Left& left, Box4& lbox, Box4& lcbox, Box4& rbox,
                        Box4& rcbox) {
    constexpr uint32_t kBlock = 64;
    uint32_t i = b, j = e;  // [i, j) not yet in place
    uint8_t offL[kBlock], offR[kBlock];
    uint32_t nL = 0, nR = 0, sL = 0, sR = 0;  // misplaced in [i, i + kBlock) and in [j - kBlock, j)
    while (j - i >= 2 * kBlock) {
        if (nL == 0) {
            sL = 0;
            for (uint32_t k = 0; k < kBlock; ++k) {
                offL[nL] = uint8_t(k);
                nL += !left(src[i + k]);
            }
        }
        if (nR == 0) {
            sR = 0;
            for (uint32_t k = 0; k < kBlock; ++k) {
                offR[nR] = uint8_t(k);
                nR += left(src[j - 1 - k]);
            }
        }
        const uint32_t m = std::min(nL, nR);
        for (uint32_t k = 0; k < m; ++k) std::swap(src[i + offL[sL + k]], src[j - 1 - offR[sR + k]]);
        nL -= m, nR -= m, sL += m, sR += m;
        if (nL == 0) i += kBlock;
        if (nR == 0) j -= kBlock;
    }
    for (;;) {
        while (i < j && left(src[i])) ++i;
        while (i < j && !left(src[j - 1])) --j;
        if (i >= j) break;
        std::swap(src[i], src[j - 1]);
    }
    auto bounds = [&](uint32_t from, uint32_t to, Box4& box, Box4& cbox) {
        Box4 bx, cb;  // locals: the stores through the references could alias the refs
        for (uint32_t k = from; k < to; ++k) extendWithCentroid(bx, cb, _mm_load_ps(src[k].lo), _mm_load_ps(src[k].hi));
        box = bx, cbox = cb;
    };
    bounds(b, i, lbox, lcbox);
    bounds(i, e, rbox, rcbox);
    return i;
}

}  // namespace rtfact
