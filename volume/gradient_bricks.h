// GradientBricks: per brick of a u8 volume, the central differences of its 9^3 samples,
// (v[i+1] - v[i-1]) per axis with the neighbours clamped into the grid, packed as three
// 10-bit signed fields in 32 bits (u8 differences lie in [-255, 255]: exact). Shaded DVR
// reads a sample's gradient from its cell's eight entries: the central difference of the
// trilinear field one voxel either side along an axis equals the trilinear interpolation
// of the voxels' differences, at the volume's border too (clamped the same way), so the
// shading is the six-sample gradient's with 8 loads instead of six trilinear samples.
// Only bricks the transfer function shows are stored; the others share brick 0 (zeros:
// no sample there contributes, so none is shaded).
#pragma once
#include <cstdint>
#include <vector>

#include "volume/brick_volume.h"

namespace rtfact::volume {

struct GradientBricks {
    static constexpr int kFieldBits = 10;
    std::vector<int32_t> entries;  // kBrick per stored brick, brick 0 all zero
    std::vector<int32_t> start;    // per brick of the grid: its first entry (0: not stored)

    bool empty() const { return start.empty(); }
    size_t memoryBytes() const { return (entries.capacity() + start.capacity()) * 4; }

    static int32_t pack(int gx, int gy, int gz) {
        constexpr int32_t m = (1 << kFieldBits) - 1;
        return (gx & m) | (gy & m) << kFieldBits | (gz & m) << (2 * kFieldBits);
    }
    // Field a (0 x, 1 y, 2 z) of an entry, sign-extended.
    static int unpack(int32_t e, int a) {
        return int32_t(uint32_t(e) << (32 - kFieldBits * (a + 1))) >> (32 - kFieldBits);
    }

    // For a u8 volume: the bricks with brickShown[b] != 0. Empty (the caller falls back to
    // six samples a gradient) when the volume is not u8 or the entries would exceed
    // maxBytes or 32-bit offsets.
    static GradientBricks build(const BrickedVolume& v, const std::vector<uint8_t>& brickShown, uint64_t maxBytes);
};

}  // namespace rtfact::volume
