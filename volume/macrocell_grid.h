// MacrocellGrid: min/max of the stored values over coarse cells of kCell^3 voxels (each
// cell also covers the next voxel layer, everything trilinear samples inside it read),
// classified per rendering mode into an occupancy flag per cell for empty-space skipping.
#pragma once
#include <cstdint>
#include <vector>

#include "volume/volume_grid.h"

namespace rtfact::volume {

struct MacrocellGrid {
    static constexpr int kCell = 8;
    int n[3] = {0, 0, 0};
    std::vector<float> lo, hi;  // stored units

    size_t count() const { return size_t(n[0]) * size_t(n[1]) * size_t(n[2]); }
    size_t index(int x, int y, int z) const { return (size_t(z) * size_t(n[1]) + size_t(y)) * size_t(n[0]) + size_t(x); }
};

MacrocellGrid buildMacrocells(const VolumeGrid& g);

}  // namespace rtfact::volume
