#include "volume/brick_volume.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <limits>

#include "core/util/error.h"
#include "core/util/huge_pages.h"
#include "core/util/memory_budget.h"

namespace rtfact::volume {

float BrickedVolume::stored(int i, int j, int k) const {
    const int bx = std::min(i / kCells, nb[0] - 1), by = std::min(j / kCells, nb[1] - 1),
              bz = std::min(k / kCells, nb[2] - 1);
    const size_t n = size_t(brickStart[brickIndex(bx, by, bz)]) + size_t(i - bx * kCells) +
                     size_t(j - by * kCells) * kEdge + size_t(k - bz * kCells) * kEdge * kEdge;
    switch (storage) {
        case Storage::U8:
            return float(pool[n]);
        case Storage::U16:
            return float(data<uint16_t>()[n]);
        default:
            return data<float>()[n];
    }
}

std::pair<float, float> BrickedVolume::valueRange() const {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (size_t b = 0; b < brickCount(); ++b) {
        lo = std::min(lo, std::min(cellLo[b] * scale + offset, cellHi[b] * scale + offset));
        hi = std::max(hi, std::max(cellLo[b] * scale + offset, cellHi[b] * scale + offset));
    }
    if (lo > hi) lo = hi = 0;
    return {lo, hi};
}

void BrickBuilder::init(BrickedVolume& v, const int dims[3], Storage s) {
    for (int a = 0; a < 3; ++a) {
        if (dims[a] < 2) throw Error("", "cannot render a volume with fewer than 2 voxels along an axis");
        v.dims[a] = dims[a];
        v.nb[a] = (dims[a] - 1 + BrickedVolume::kCells - 1) / BrickedVolume::kCells;
    }
    v.storage = s;
    const size_t nbricks = v.brickCount();
    v.brickStart.assign(nbricks, 0);
    v.cellLo.assign(nbricks, 0.0f);
    v.cellHi.assign(nbricks, 0.0f);
    v.subLo.assign(nbricks * 8, 0.0f);
    v.subHi.assign(nbricks * 8, 0.0f);
    // brick 0: zeros, plus padding so wide gathers may over-read at the end
    v.pool.assign(size_t(BrickedVolume::kBrick) * size_t(storageBytes(s)), 0);
}

void BrickBuilder::finish(BrickedVolume& v) {
    if (v.pool.size() / size_t(storageBytes(v.storage)) > size_t(std::numeric_limits<int32_t>::max()) - 64)
        throw Error("", "volume too large for 32-bit brick offsets");
    // padding so wide gathers may over-read at the end (dense bricking allocates it)
    if (v.pool.size() % (size_t(BrickedVolume::kBrick) * size_t(storageBytes(v.storage))) == 0) {
        v.pool.resize(v.pool.size() + 64, 0);
        v.pool.shrink_to_fit();
    }
    buildMarchCopy(v);
}

namespace {
// Fills a march copy of v.pool (BrickedVolume::pairs or quads): entry (x, y, z) of a brick,
// for x < kEdge, y < kCells, z < zCount, holds the K pool samples at (x, y, z) + offs[k]
// (pool offsets); entries are x-major with the layout's row and slice strides.
template <class T, int K>
void fillCopy(BrickedVolume& v, std::vector<uint8_t>& copy, int zCount, int row, int slice, const int (&offs)[K]) {
    using BV = BrickedVolume;
    const size_t bricks = v.pool.size() / (size_t(BV::kBrick) * sizeof(T));
    const size_t entries = size_t(slice) * size_t(zCount);
    const T* src = v.data<T>();
    T* dst = reinterpret_cast<T*>(copy.data());
    tbb::parallel_for(size_t(0), bricks, [&](size_t b) {
        const T* s = src + b * size_t(BV::kBrick);
        T* d = dst + b * entries * K;
        for (int z = 0; z < zCount; ++z)
            for (int y = 0; y < BV::kCells; ++y)
                for (int x = 0; x < BV::kEdge; ++x) {
                    const T* c = s + x + y * BV::kEdge + z * BV::kEdge * BV::kEdge;
                    T* e = d + size_t(x + y * row + z * slice) * K;
                    for (int k = 0; k < K; ++k) e[k] = c[offs[k]];
                }
    });
}
}  // namespace

bool buildMarchCopy(BrickedVolume& v, bool allowQuads) {
    using BV = BrickedVolume;
    for (auto* copy : {&v.pairs, &v.quads}) {
        copy->clear();
        copy->shrink_to_fit();
    }
    if (v.storage == Storage::F32) return false;
    const size_t bytes = size_t(storageBytes(v.storage));
    const size_t bricks = v.pool.size() / (size_t(BV::kBrick) * bytes);
    // Up to 256 MB. Session s6 kept it cache-sized (16 MB): large copies were slower, the
    // march waiting on cache misses. Since the march prefetches the copy's bricks ahead
    // (VolumeScene::prefetchBricks) the halved fetches pay there too (Zen 5, 1 thread: AVX2
    // bonsai with 26 MB of quads -7%, 256^3 u16 phantom with 25 MB of pairs -8% AVX-512 /
    // -12% AVX2, 512^3 phantom with 183 MB of pairs -8% to -12% at every step). Optional:
    // keep a quarter of what is available for everything else (frame buffers, a second
    // scene), else render from the pool alone. Entries are addressed with 32-bit indices,
    // like the pool's samples.
    constexpr uint64_t kMaxCopyBytes = uint64_t(256) << 20;
    const auto fits = [&](int entries, size_t entryBytes) {
        const uint64_t need = uint64_t(bricks) * uint64_t(entries) * entryBytes + 64;
        return uint64_t(bricks) * uint64_t(entries) <= uint64_t(std::numeric_limits<int32_t>::max()) - 64 &&
               need <= kMaxCopyBytes && need <= availableMemoryBytes() / 4 * 3;
    };
    if (v.storage == Storage::U8 && allowQuads && fits(BV::kQuadEntries, 4)) {
        resizeFreshHugePages(v.quads, size_t(bricks) * BV::kQuadEntries * 4 + 64);
        constexpr int kYZQuad[4] = {0, BV::kEdge, BV::kEdge * BV::kEdge, BV::kEdge + BV::kEdge * BV::kEdge};
        fillCopy<uint8_t>(v, v.quads, BV::kCells, BV::kQuadRow, BV::kQuadSlice, kYZQuad);
        return true;
    }
    if (!fits(BV::kPairEntries, 2 * bytes)) return false;
    resizeFreshHugePages(v.pairs, size_t(bricks) * BV::kPairEntries * 2 * bytes + 64);
    constexpr int kYPair[2] = {0, BV::kEdge};
    if (v.storage == Storage::U8)
        fillCopy<uint8_t>(v, v.pairs, BV::kEdge, BV::kPairRow, BV::kPairSlice, kYPair);
    else
        fillCopy<uint16_t>(v, v.pairs, BV::kEdge, BV::kPairRow, BV::kPairSlice, kYPair);
    return true;
}

namespace {
template <class T>
void brickDense(VolumeGrid& g, BrickedVolume& v, bool release) {
    const T* src = g.data<T>();
    const size_t nb = v.brickCount();
    // Pass 1: which bricks are all zero (share brick 0) and where the others go.
    std::vector<uint8_t> zero(nb, 0);
    tbb::parallel_for(size_t(0), nb, [&](size_t b) {
        const int bx = int(b % size_t(v.nb[0])), by = int((b / size_t(v.nb[0])) % size_t(v.nb[1])),
                  bz = int(b / (size_t(v.nb[0]) * size_t(v.nb[1])));
        bool allZero = true;
        for (int k = 0; k < BrickedVolume::kEdge && allZero; ++k) {
            const int z = std::min(bz * BrickedVolume::kCells + k, g.dims[2] - 1);
            for (int j = 0; j < BrickedVolume::kEdge && allZero; ++j) {
                const int y = std::min(by * BrickedVolume::kCells + j, g.dims[1] - 1);
                const T* row = src + g.index(0, y, z);
                for (int i = 0; i < BrickedVolume::kEdge; ++i)
                    if (row[std::min(bx * BrickedVolume::kCells + i, g.dims[0] - 1)] != T(0)) {
                        allZero = false;
                        break;
                    }
            }
        }
        zero[b] = allZero;
    });
    std::vector<int64_t> start(nb, 0);
    int64_t next = BrickedVolume::kBrick;
    for (size_t b = 0; b < nb; ++b)
        if (!zero[b]) {
            start[b] = next;
            next += BrickedVolume::kBrick;
        }
    if (next > int64_t(std::numeric_limits<int32_t>::max()) - 64)
        throw Error("", "volume too large for 32-bit brick offsets");
    resizeFreshHugePages(v.pool, size_t(next) * sizeof(T) + 64);
    T* pool = reinterpret_cast<T*>(v.pool.data());
    // Pass 2 by z-slabs of bricks, so the dense slab can be released behind us.
    for (int bz = 0; bz < v.nb[2]; ++bz) {
        tbb::parallel_for(0, v.nb[1], [&](int by) {
            for (int bx = 0; bx < v.nb[0]; ++bx) {
                const size_t b = v.brickIndex(bx, by, bz);
                v.brickStart[b] = int32_t(start[b]);
                if (zero[b]) continue;
                T* dst = pool + start[b];
                int n = 0;
                for (int k = 0; k < BrickedVolume::kEdge; ++k) {
                    const int z = std::min(bz * BrickedVolume::kCells + k, g.dims[2] - 1);
                    for (int j = 0; j < BrickedVolume::kEdge; ++j) {
                        const int y = std::min(by * BrickedVolume::kCells + j, g.dims[1] - 1);
                        const T* row = src + g.index(0, y, z);
                        for (int i = 0; i < BrickedVolume::kEdge; ++i, ++n) {
                            const T s = row[std::min(bx * BrickedVolume::kCells + i, g.dims[0] - 1)];
                            dst[n] = s;
                        }
                    }
                }
                setBrickRanges(v, b, dst);
            }
        });
    }
    (void)release;
}
}  // namespace

BrickedVolume brickVolume(VolumeGrid& g, bool release) {
    BrickedVolume v;
    BrickBuilder::init(v, g.dims, g.storage);
    v.spacing = g.spacing;
    v.origin = g.origin;
    v.scale = g.scale;
    v.offset = g.offset;
    v.sourceType = g.sourceType;
    v.meta = g.meta;
    switch (g.storage) {
        case Storage::U8:
            brickDense<uint8_t>(g, v, release);
            break;
        case Storage::U16:
            brickDense<uint16_t>(g, v, release);
            break;
        default:
            brickDense<float>(g, v, release);
            break;
    }
    if (release) {
        g.bytes.clear();
        g.bytes.shrink_to_fit();
    }
    BrickBuilder::finish(v);
    return v;
}

}  // namespace rtfact::volume
