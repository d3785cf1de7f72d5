// spreadAxis: the axis along which a range of discs' centres spread most, the split axis
// of the wide LoD BVH's median splits (points/lod_wide_bvh.h). Estimated from at most
// kSpreadAxisSamples centres evenly strided over the range (all of a smaller one): the
// extent of the discs themselves, not of the parent's cell halved at the median. On a
// surface a cell keeps its parent's width across the surface, and splits across it cut
// clusters into slivers: against the cell the dragon's wide BVH traced full detail and
// LoD faster (docs/benchmarks.md, session 37). The kd-tree keeps the cell's axis: there
// the spread axis lowered the bunny's LoD image at quality 8 (28.1 -> 26.5 dB).
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "core/math/aabb.h"
#include "points/disc.h"

namespace rtfact::points {

inline constexpr size_t kSpreadAxisSamples = 128;

inline int spreadAxis(const Disc* d, size_t n) {
    const size_t m = std::min(n, kSpreadAxisSamples);
    AABB box;
    for (size_t i = 0; i < m; ++i) box.extend(d[(2 * uint64_t(i) + 1) * n / (2 * m)].center);
    return box.maxAxis();
}

}  // namespace rtfact::points
