#include "volume/value_histogram.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace rtfact::volume {

size_t ValueHistogram::binOf(float v) const {
    const double f = (double(v) - double(origin)) / double(width);
    if (!(f > 0)) return 0;
    return size_t(std::min(double(bins.size() - 1), f));
}

uint64_t ValueHistogram::count(size_t first, size_t last) const {
    uint64_t n = 0;
    for (size_t i = first; i <= last && i < bins.size(); ++i) n += bins[i];
    return n;
}

float ValueHistogram::percentile(double p, size_t first) const {
    if (first >= bins.size()) return hi;
    const uint64_t n = count(first, bins.size() - 1);
    const double target = std::clamp(p, 0.0, 1.0) * double(n);
    uint64_t run = 0;
    for (size_t i = first; i < bins.size(); ++i) {
        run += bins[i];
        if (run > 0 && double(run) >= target) return std::clamp(binCenter(i), lo, hi);
    }
    return hi;
}

ValueHistogram emptyHistogram(float lo, float hi, float step, int maxBins) {
    ValueHistogram h;
    h.lo = lo;
    h.hi = std::max(lo, hi);
    maxBins = std::max(maxBins, 1);
    const double range = double(h.hi) - double(lo);
    size_t n = 1;
    if (step > 0 && range / double(step) < 1e9) {
        const double values = std::floor(range / double(step) + 0.5) + 1.0;  // distinct stored values
        const double per = std::ceil(values / double(maxBins));
        h.width = float(per * double(step));
        h.origin = float(double(lo) - 0.5 * double(step));
        n = size_t(std::ceil(values / per));
    } else if (range > 0) {
        n = size_t(maxBins);
        h.width = float(range / double(maxBins));
        h.origin = lo;
    } else {
        h.origin = lo - 0.5f;
    }
    if (!(h.width > 0)) h.width = 1;
    h.bins.assign(n, 0);
    return h;
}

namespace {

// Per-thread bins, summed at the end.
struct BinSum {
    explicit BinSum(const ValueHistogram& h) : local([&h] { return std::vector<uint64_t>(h.bins.size(), 0); }) {}
    tbb::enumerable_thread_specific<std::vector<uint64_t>> local;
    void into(ValueHistogram& h) {
        for (const auto& l : local)
            for (size_t i = 0; i < l.size(); ++i) h.bins[i] += l[i];
        h.total = h.count(0, h.bins.size() - 1);
    }
};

float dataStep(Storage s, float scale) { return s == Storage::F32 ? 0.0f : std::fabs(scale); }

template <class T>
ValueHistogram denseHistogram(const VolumeGrid& g, int maxBins) {
    const T* src = g.data<T>();
    const size_t n = g.voxelCount();
    using Range = std::pair<float, float>;
    tbb::enumerable_thread_specific<Range> ranges(
        Range{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()});
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
        Range& m = ranges.local();
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const float v = float(src[i]) * g.scale + g.offset;
            if (!std::isfinite(v)) continue;
            m.first = std::min(m.first, v);
            m.second = std::max(m.second, v);
        }
    });
    Range all{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
    for (const Range& m : ranges) all = {std::min(all.first, m.first), std::max(all.second, m.second)};
    if (all.first > all.second) all = {0.0f, 0.0f};
    ValueHistogram h = emptyHistogram(all.first, all.second, dataStep(g.storage, g.scale), maxBins);
    BinSum sum(h);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<uint64_t>& bins = sum.local.local();
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const float v = float(src[i]) * g.scale + g.offset;
            if (std::isfinite(v)) ++bins[h.binOf(v)];
        }
    });
    sum.into(h);
    return h;
}

template <class T>
void brickCounts(const BrickedVolume& v, ValueHistogram& h) {
    BinSum sum(h);
    const T* pool = v.data<T>();
    const int C = BrickedVolume::kCells, E = BrickedVolume::kEdge;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, v.brickCount()), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<uint64_t>& bins = sum.local.local();
        for (size_t b = r.begin(); b != r.end(); ++b) {
            const int bx = int(b % size_t(v.nb[0])), by = int((b / size_t(v.nb[0])) % size_t(v.nb[1])),
                      bz = int(b / (size_t(v.nb[0]) * size_t(v.nb[1])));
            // A brick owns its first 8 samples per axis; the last brick also its shared layer.
            const int ex = bx == v.nb[0] - 1 ? v.dims[0] - bx * C : C, ey = by == v.nb[1] - 1 ? v.dims[1] - by * C : C,
                      ez = bz == v.nb[2] - 1 ? v.dims[2] - bz * C : C;
            if (v.brickStart[b] == 0) {  // the shared zero brick
                const float zero = v.offset;
                if (std::isfinite(zero)) bins[h.binOf(zero)] += uint64_t(ex) * uint64_t(ey) * uint64_t(ez);
                continue;
            }
            const T* s = pool + v.brickStart[b];
            for (int k = 0; k < ez; ++k)
                for (int j = 0; j < ey; ++j)
                    for (int i = 0; i < ex; ++i) {
                        const float val = float(s[(k * E + j) * E + i]) * v.scale + v.offset;
                        if (std::isfinite(val)) ++bins[h.binOf(val)];
                    }
        }
    });
    sum.into(h);
}

}  // namespace

ValueHistogram histogramOf(const VolumeGrid& g, int maxBins) {
    switch (g.storage) {
        case Storage::U8:
            return denseHistogram<uint8_t>(g, maxBins);
        case Storage::U16:
            return denseHistogram<uint16_t>(g, maxBins);
        default:
            return denseHistogram<float>(g, maxBins);
    }
}

ValueHistogram histogramOf(const BrickedVolume& v, int maxBins) {
    const auto [lo, hi] = v.valueRange();
    ValueHistogram h = emptyHistogram(lo, hi, dataStep(v.storage, v.scale), maxBins);
    switch (v.storage) {
        case Storage::U8:
            brickCounts<uint8_t>(v, h);
            break;
        case Storage::U16:
            brickCounts<uint16_t>(v, h);
            break;
        default:
            brickCounts<float>(v, h);
            break;
    }
    return h;
}

}  // namespace rtfact::volume
