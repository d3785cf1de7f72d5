// BrickedVolume: the render-time layout of a volume. Voxels live in bricks of 8^3 cells
// stored as 9^3 samples (one shared layer with the next brick), so every trilinear cell
// lies inside one brick and neighbouring rays hit the same few cache lines; bricks that
// are entirely zero share one brick, which makes sparse (OpenVDB) volumes cheap without
// a dense copy. The brick grid doubles as the macrocell grid for empty-space skipping:
// per brick the min/max of its 9^3 samples (everything a sample inside it reads).
#pragma once
#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/math/aabb.h"
#include "volume/volume_grid.h"

namespace rtfact::volume {

struct BrickedVolume {
    static constexpr int kCells = 8;                      // cells per brick edge
    static constexpr int kEdge = kCells + 1;              // samples per brick edge
    static constexpr int kBrick = kEdge * kEdge * kEdge;  // samples per brick

    int dims[3] = {0, 0, 0};
    int nb[3] = {0, 0, 0};  // bricks per axis
    Vec3f spacing{1, 1, 1}, origin{0, 0, 0};
    Storage storage = Storage::U8;
    float scale = 1.0f, offset = 0.0f;
    std::string sourceType;
    VolumeMetadata meta;
    std::vector<uint8_t> pool;          // bricks of kBrick samples; brick 0 is all zero
    std::vector<int32_t> brickStart;    // per brick: first sample in the pool
    std::vector<float> cellLo, cellHi;  // per brick: stored min/max
    // Per brick and octant (index b * 8 + ox + 2 oy + 4 oz): the stored min/max of the
    // octant's 5^3 samples, everything a sample in its 4^3 cells reads: the finer grid of
    // empty-space skipping. setBrickRanges fills both from a brick's samples.
    static constexpr int kSubCells = kCells / 2;
    std::vector<float> subLo, subHi;
    // u8/u16 only, a second copy of the pool for the march, in one of two layouts (at most
    // one is built; buildMarchCopy):
    //  - y-z quads (u8): pool brick b is quad brick b of kQuadEntries entries of 4 samples;
    //    entry (x, y, z), y, z < kCells, holds (x, y, z), (x, y + 1, z), (x, y, z + 1) and
    //    (x, y + 1, z + 1), so one 64-bit load at (x, y, z) returns the cell's eight corners:
    //    a trilinear sample is one gather (3.2x the pool's bytes).
    //  - y-pairs (u8/u16): pool brick b is pair brick b of kPairEntries entries; entry
    //    (x, y, z), y < kCells, holds the samples (x, y, z) and (x, y + 1, z), so one 32-bit
    //    (u8) or 64-bit (u16) load at (x, y, z) returns the four corners of a cell face: a
    //    trilinear sample is 2 gathers, not 4 (1.78x the pool).
    // Built up to 256 MB (buildMarchCopy: past it the memory outweighs the gain) where the
    // memory budget allows it; both empty otherwise, and the march reads the pool.
    static constexpr int kPairRow = kEdge, kPairSlice = kEdge * kCells, kPairEntries = kPairSlice * kEdge;
    static constexpr int kQuadRow = kEdge, kQuadSlice = kEdge * kCells, kQuadEntries = kQuadSlice * kCells;
    std::vector<uint8_t> pairs, quads;

    size_t brickCount() const { return size_t(nb[0]) * size_t(nb[1]) * size_t(nb[2]); }
    size_t brickIndex(int bx, int by, int bz) const {
        return (size_t(bz) * size_t(nb[1]) + size_t(by)) * size_t(nb[0]) + size_t(bx);
    }
    size_t voxelCount() const { return size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]); }
    // non-empty bricks (brick 0, the shared zero brick, not counted)
    size_t storedBricks() const { return pool.size() / (size_t(kBrick) * size_t(storageBytes(storage))) - 1; }
    size_t memoryBytes() const {
        return pool.capacity() + pairs.capacity() + quads.capacity() + brickStart.capacity() * 4 +
               (cellLo.capacity() + cellHi.capacity() + subLo.capacity() + subHi.capacity()) * 4;
    }
    template <class T>
    const T* data() const {
        return reinterpret_cast<const T*>(pool.data());
    }
    AABB bounds() const {
        const Vec3f ext((dims[0] - 1) * spacing.x, (dims[1] - 1) * spacing.y, (dims[2] - 1) * spacing.z);
        return {origin, origin + ext};
    }
    // Stored value at voxel (i, j, k) (for tests and tools, not the hot path).
    float stored(int i, int j, int k) const;
    // Data value range over all bricks.
    std::pair<float, float> valueRange() const;
};

// Bricks a dense grid (parallel). `release` frees the grid's voxels as bricks are
// made, so peak memory stays near one copy.
BrickedVolume brickVolume(VolumeGrid& grid, bool release = false);
inline BrickedVolume brickVolume(const VolumeGrid& grid) { return brickVolume(const_cast<VolumeGrid&>(grid), false); }

// Allocation of bricks for sparse sources: call `reserve` with the number of non-zero
// bricks, then fill them one by one.
struct BrickBuilder {
    // Sets up dims/nb/tables; the pool holds brick 0 (zeros).
    static void init(BrickedVolume& v, const int dims[3], Storage s);
    // Appends a brick filled by fill(i, j, k) -> stored value for local samples.
    template <class F>
    static void addBrick(BrickedVolume& v, int bx, int by, int bz, F&& fill);
    // Checks the offsets, pads the pool and builds the march's copy (buildMarchCopy).
    static void finish(BrickedVolume& v);
};

// Sets brick b's value ranges (cellLo/cellHi and its octants' subLo/subHi) from its
// kBrick samples s (x fastest).
template <class T>
void setBrickRanges(BrickedVolume& v, size_t b, const T* s) {
    constexpr int E = BrickedVolume::kEdge, H = BrickedVolume::kSubCells;
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (int o = 0; o < 8; ++o) {
        const int x0 = (o & 1) * H, y0 = (o >> 1 & 1) * H, z0 = (o >> 2) * H;
        float olo = std::numeric_limits<float>::infinity(), ohi = -olo;
        for (int k = z0; k <= z0 + H; ++k)
            for (int j = y0; j <= y0 + H; ++j)
                for (int i = x0; i <= x0 + H; ++i) {
                    const float x = float(s[(k * E + j) * E + i]);
                    olo = std::min(olo, x);
                    ohi = std::max(ohi, x);
                }
        v.subLo[b * 8 + size_t(o)] = olo;
        v.subHi[b * 8 + size_t(o)] = ohi;
        lo = std::min(lo, olo);
        hi = std::max(hi, ohi);
    }
    v.cellLo[b] = lo;
    v.cellHi[b] = hi;
}

// Builds the march's copy of v.pool for u8/u16 volumes (y-z quads for u8, y-pairs for u16
// or where the quads would not fit) when it is at most 256 MB and the memory budget allows
// it (core/util/memory_budget.h), else leaves both empty. Returns whether one was built.
// allowQuads = false builds y-pairs for u8 too (tests compare the layouts).
bool buildMarchCopy(BrickedVolume& v, bool allowQuads = true);

template <class F>
void BrickBuilder::addBrick(BrickedVolume& v, int bx, int by, int bz, F&& fill) {
    const size_t bytes = size_t(BrickedVolume::kBrick) * size_t(storageBytes(v.storage));
    const size_t start = v.pool.size();
    v.pool.resize(start + bytes);
    uint8_t* dst = v.pool.data() + start;
    int n = 0;
    for (int k = 0; k < BrickedVolume::kEdge; ++k)
        for (int j = 0; j < BrickedVolume::kEdge; ++j)
            for (int i = 0; i < BrickedVolume::kEdge; ++i, ++n) {
                const float s = fill(bx * BrickedVolume::kCells + i, by * BrickedVolume::kCells + j,
                                     bz * BrickedVolume::kCells + k);
                if (v.storage == Storage::U8)
                    dst[n] = uint8_t(s);
                else if (v.storage == Storage::U16)
                    reinterpret_cast<uint16_t*>(dst)[n] = uint16_t(s);
                else
                    reinterpret_cast<float*>(dst)[n] = s;
            }
    const size_t b = v.brickIndex(bx, by, bz);
    v.brickStart[b] = int32_t(start / size_t(storageBytes(v.storage)));
    if (v.storage == Storage::U8)
        setBrickRanges(v, b, dst);
    else if (v.storage == Storage::U16)
        setBrickRanges(v, b, reinterpret_cast<const uint16_t*>(dst));
    else
        setBrickRanges(v, b, reinterpret_cast<const float*>(dst));
}

}  // namespace rtfact::volume
