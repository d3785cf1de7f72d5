// selectByCoordinate: nth_element of discs by one centre coordinate, branch-free for
// large ranges (the LoD builders' median splits).
#pragma once
#include <algorithm>
#include <cstddef>

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

// nth_element by coordinate with the postcondition of std::nth_element. std::nth_element's
// branchy partitions were ~80% of the build; here each round partitions around a pivot
// estimated from a stratified sample at the target rank (Floyd-Rivest style), so the
// range shrinks to about a tenth per pass and the passes are branch-free.
inline void selectByCoordinate(Disc* d, size_t n, size_t k, int axis) {
    auto less = [axis](const Disc& x, const Disc& y) { return x.center[axis] < y.center[axis]; };
    while (n > 12) {
        const size_t samples = std::min<size_t>(31, n / 4);
        float sample[31];
        for (size_t s = 0; s < samples; ++s) sample[s] = d[(2 * s + 1) * n / (2 * samples)].center[axis];
        std::sort(sample, sample + samples);
        // Pivot just above the target's estimated rank, so that k usually falls left.
        const size_t r = std::min(samples - 1, k * samples / n + (samples > 8 ? 2 : 1));
        const size_t j = partitionBelow(d, n, axis, sample[r]);
        if (k < j) {
            n = j;
        } else if (j > 0) {
            d += j;
            k -= j;
            n -= j;
        } else {
            break;  // no disc below the pivot (ties): let std::nth_element finish
        }
    }
    std::nth_element(d, d + k, d + n, less);
}

// Ranges above this use selectByCoordinate; below it std::nth_element, whose choice among
// equal coordinates the kd-tree's scanned-cloud LoD references bake in.
inline constexpr size_t kFastSelect = size_t(1) << 16;

inline void selectMedianByCoordinate(Disc* d, size_t n, size_t k, int axis) {
    if (n > kFastSelect)
        selectByCoordinate(d, n, k, axis);
    else
        std::nth_element(d, d + k, d + n,
                         [axis](const Disc& x, const Disc& y) { return x.center[axis] < y.center[axis]; });
}

}  // namespace rtfact::points
