// centreBounds: the box of the discs' centres, the root cell of both LoD builders'
// median splits. Computed on all threads: nothing else can run before the first split.
#pragma once
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <span>

#include "core/math/aabb.h"
#include "points/disc.h"

namespace rtfact::points {

inline AABB centreBounds(std::span<const Disc> discs) {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, discs.size(), size_t(1) << 16), AABB{},
        [&](const tbb::blocked_range<size_t>& r, AABB box) {
            for (size_t i = r.begin(); i < r.end(); ++i) box.extend(discs[i].center);
            return box;
        },
        [](const AABB& a, const AABB& b) { return merge(a, b); });
}

}  // namespace rtfact::points
