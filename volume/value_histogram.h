// ValueHistogram: how many voxels hold each data value, the input for choosing a default
// transfer function. Integer-stored data get bins that are whole multiples of one stored
// step, each step centred in its bin, so no bin is empty merely because of rounding (a
// 0..1826 u16 volume over 1024 equal bins would leave a comb of alternating 1- and
// 2-value bins).
#pragma once
#include <cstdint>
#include <vector>

#include "volume/brick_volume.h"
#include "volume/volume_grid.h"

namespace rtfact::volume {

struct ValueHistogram {
    float lo = 0, hi = 0;         // finite data range
    float origin = 0, width = 1;  // bin i covers [origin + i * width, origin + (i + 1) * width)
    std::vector<uint64_t> bins;
    uint64_t total = 0;  // voxels counted (finite values)

    size_t binOf(float v) const;
    float binLo(size_t i) const { return origin + float(i) * width; }
    float binCenter(size_t i) const { return origin + (float(i) + 0.5f) * width; }
    // Voxels with values in bins [first, last].
    uint64_t count(size_t first, size_t last) const;
    // Smallest bin centre below or at which a fraction p (0..1) of the voxels in bins
    // [first, end) lie, clamped to [lo, hi].
    float percentile(double p, size_t first = 0) const;
};

// Sets up empty bins for data in [lo, hi]; `step` > 0 is the data step of integer storage
// (|scale|), 0 for float data. At most maxBins bins.
ValueHistogram emptyHistogram(float lo, float hi, float step, int maxBins = 1024);
// All finite voxels of a dense grid, or of a bricked volume (every voxel once, the shared
// zero brick included; a sparse volume's inactive space counts as zero).
ValueHistogram histogramOf(const VolumeGrid& g, int maxBins = 1024);
ValueHistogram histogramOf(const BrickedVolume& v, int maxBins = 1024);

}  // namespace rtfact::volume
