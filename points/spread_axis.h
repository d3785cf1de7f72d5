// spreadAxis: the axis along which a range of discs' centres spread most, the split axis
// of both LoD builders' median splits (the kd-tree and the wide BVH). Estimated from at
// most kSpreadAxisSamples centres evenly strided over the range (all of a smaller one):
// the extent of the discs themselves, not of the parent's cell halved at the median. On a
// surface a cell keeps its parent's width across the surface, and splits across it cut
// clusters into slivers: against the cell, full detail traced 9-28% faster on real scans
// and LoD 16-30% faster at equal PSNR (docs/benchmarks.md, session 37).
#pragma once
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>

#include "core/math/aabb.h"
#include "points/disc.h"

namespace rtfact::points {

inline constexpr size_t kSpreadAxisSamples = 128;

// Sample i of a larger range is centre (2i + 1) n / (2 kSpreadAxisSamples): a shift, not
// the 64-bit division per sample that was most of this function's time in a LoD build.
inline int spreadAxis(const Disc* d, size_t n) {
    static_assert(std::has_single_bit(kSpreadAxisSamples));
    constexpr int kShift = std::countr_zero(2 * kSpreadAxisSamples);
    AABB box;
    if (n <= kSpreadAxisSamples) {
        for (size_t i = 0; i < n; ++i) box.extend(d[i].center);
    } else {
        for (uint64_t i = 0; i < kSpreadAxisSamples; ++i) box.extend(d[((2 * i + 1) * n) >> kShift].center);
    }
    return box.maxAxis();
}

}  // namespace rtfact::points
