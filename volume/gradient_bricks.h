// GradientBricks: per brick of a volume, the central differences of its 9^3 samples,
// (v[i+1] - v[i-1]) per axis with the neighbours clamped into the grid, packed exactly for
// integer voxels: u8 differences (in [-255, 255]) as three 10-bit fields of one 32-bit
// word, u16 ones (in [-65535, 65535]) in two words; f32 ones as three floats. Shaded DVR
// reads a sample's gradient from its cell's eight entries: the central difference of the
// trilinear field one voxel either side along an axis equals the trilinear interpolation
// of the voxels' differences, at the volume's border too (clamped the same way), so the
// shading is the six-sample gradient's (to float rounding) with 8, 16 or 24 32-bit loads
// instead of six trilinear samples. Only bricks the transfer function shows are stored;
// the others share brick 0 (zeros: no sample there contributes, so none is shaded).
#pragma once
#include <cstdint>
#include <vector>

#include "core/simd/native.h"
#include "volume/brick_volume.h"

namespace rtfact::volume {

struct GradientBricks {
    int words = 0;                 // 32-bit words an entry: 1 (u8), 2 (u16), 3 (f32); 0: none built
    std::vector<int32_t> entries;  // u8, u16: kBrick entries per stored brick, brick 0 all zero
    std::vector<float> values;     // f32: the same as (x, y, z) floats
    std::vector<int32_t> start;    // per brick of the grid: its first word (0: not stored)

    bool empty() const { return words == 0; }
    size_t memoryBytes() const { return (entries.capacity() + values.capacity() + start.capacity()) * 4; }

    // An entry of voxels of Bytes bytes (1: u8, 2: u16) from its differences.
    template <int Bytes>
    static void pack(int gx, int gy, int gz, int32_t* w) {
        if constexpr (Bytes == 1) {
            w[0] = (gx & 0x3ff) | (gy & 0x3ff) << 10 | (gz & 0x3ff) << 20;
        } else {
            // halves of x and y (16 bits each); z (18 bits) and the halves' low bits
            w[0] = ((gx >> 1) & 0xffff) | (gy >> 1) << 16;
            w[1] = (gz & 0x3ffff) | (gx & 1) << 30 | (gy & 1) << 31;
        }
    }
    // The differences of an entry (words w), for I = int32_t or Packet<W, int32_t>: fields
    // sign-extended by a shift to the top bits and an arithmetic shift down.
    template <int Bytes, class I>
    static RTFACT_INLINE void decode(const I (&w)[Bytes], I (&g)[3]) {
        if constexpr (Bytes == 1) {
            for (int a = 0; a < 3; ++a) g[a] = (w[0] << (22 - 10 * a)) >> 22;
        } else {
            g[0] = ((w[0] << 16) >> 16) * I(2) + ((w[1] >> 30) & I(1));
            g[1] = (w[0] >> 16) * I(2) + ((w[1] >> 31) & I(1));
            g[2] = (w[1] << 14) >> 14;
        }
    }

    // The bricks with brickShown[b] != 0. Empty (the caller falls back to six samples a
    // gradient) when the entries would exceed maxBytes or 32-bit offsets.
    static GradientBricks build(const BrickedVolume& v, const std::vector<uint8_t>& brickShown, uint64_t maxBytes);
};

}  // namespace rtfact::volume
