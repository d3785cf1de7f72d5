// Statistics of a loaded grid for `rtfact info`: range, mean and a histogram.
#include <algorithm>
#include <cmath>
#include <limits>

#include "volume/volume_grid.h"

namespace rtfact::volume {

VolumeSummary summarize(const VolumeGrid& g, int bins) {
    VolumeSummary s;
    const size_t n = g.voxelCount();
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    double sum = 0;
    for (size_t i = 0; i < n; ++i) {
        const float v = g.value(i);
        if (!std::isfinite(v)) {
            ++s.nonFinite;
            continue;
        }
        lo = std::min(lo, v);
        hi = std::max(hi, v);
        sum += v;
    }
    if (lo > hi) lo = hi = 0;
    s.lo = lo;
    s.hi = hi;
    s.mean = n ? sum / double(n) : 0.0;
    s.histogram.assign(size_t(std::max(bins, 1)), 0);
    const float inv = hi > lo ? float(bins) / (hi - lo) : 0.0f;
    for (size_t i = 0; i < n; ++i) {
        const float v = g.value(i);
        if (!std::isfinite(v)) continue;
        s.histogram[size_t(std::min(bins - 1, int((v - lo) * inv)))]++;
    }
    return s;
}

}  // namespace rtfact::volume
