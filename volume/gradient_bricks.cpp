#include "volume/gradient_bricks.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <utility>

#include "core/util/huge_pages.h"

namespace rtfact::volume {

namespace {
template <class T>
void fill(const BrickedVolume& v, const std::vector<uint8_t>& brickShown, GradientBricks& g) {
    using BV = BrickedVolume;
    const T* pool = v.data<T>();
    constexpr int E = BV::kEdge, C = BV::kCells, N = E + 2;  // N: the brick and one voxel around it
    tbb::parallel_for(size_t(0), v.brickCount(), [&](size_t b) {
        if (!brickShown[b]) return;
        const int bc[3] = {int(b % size_t(v.nb[0])), int(b / size_t(v.nb[0]) % size_t(v.nb[1])),
                           int(b / (size_t(v.nb[0]) * size_t(v.nb[1])))};
        // per axis and local position -1 .. kEdge: the voxel's brick and its place there,
        // clamped into the grid
        int brickOf[3][N], localOf[3][N];
        for (int a = 0; a < 3; ++a)
            for (int i = 0; i < N; ++i) {
                const int x = std::clamp(bc[a] * C + i - 1, 0, v.dims[a] - 1);
                brickOf[a][i] = std::min(x / C, v.nb[a] - 1);
                localOf[a][i] = x - brickOf[a][i] * C;
            }
        T around[N * N * N];
        for (int k = 0; k < N; ++k)
            for (int j = 0; j < N; ++j) {
                const int32_t* rowStart = v.brickStart.data() + v.brickIndex(0, brickOf[1][j], brickOf[2][k]);
                const int yz = localOf[1][j] * E + localOf[2][k] * E * E;
                T* dst = around + (k * N + j) * N;
                for (int i = 0; i < N; ++i) dst[i] = pool[rowStart[brickOf[0][i]] + localOf[0][i] + yz];
            }
        int32_t* out = g.entries.data() + g.start[b];
        for (int k = 1; k <= E; ++k)
            for (int j = 1; j <= E; ++j)
                for (int i = 1; i <= E; ++i, out += sizeof(T)) {
                    const int c = (k * N + j) * N + i;
                    GradientBricks::pack<sizeof(T)>(int(around[c + 1]) - int(around[c - 1]),
                                                    int(around[c + N]) - int(around[c - N]),
                                                    int(around[c + N * N]) - int(around[c - N * N]), out);
                }
    });
}
}  // namespace

GradientBricks GradientBricks::build(const BrickedVolume& v, const std::vector<uint8_t>& brickShown,
                                     uint64_t maxBytes) {
    using BV = BrickedVolume;
    GradientBricks g;
    const size_t nb = v.brickCount();
    if (v.storage == Storage::F32 || brickShown.size() != nb) return g;
    const int words = storageBytes(v.storage);
    // brick 0 (zeros) and the shown ones
    const uint64_t bricks =
        1 + uint64_t(std::count_if(brickShown.begin(), brickShown.end(), [](uint8_t s) { return s; }));
    const uint64_t count = bricks * uint64_t(BV::kBrick * words);
    if (count * 4 > maxBytes || count + 64 > uint64_t(std::numeric_limits<int32_t>::max())) return g;
    g.start.assign(nb, 0);
    int32_t next = BV::kBrick * words;
    for (size_t b = 0; b < nb; ++b)
        if (brickShown[b]) g.start[b] = std::exchange(next, next + BV::kBrick * words);
    // + 64: wide gathers may read past the last entry; on huge pages (4 KiB page faults
    // took most of the build)
    resizeHugePages(g.entries, size_t(count) + 64);
    if (words == 1)
        fill<uint8_t>(v, brickShown, g);
    else
        fill<uint16_t>(v, brickShown, g);
    g.words = words;
    return g;
}

}  // namespace rtfact::volume
