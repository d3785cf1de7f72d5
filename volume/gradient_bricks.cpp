#include "volume/gradient_bricks.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <type_traits>
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
        for (int k = 1, e = g.start[b]; k <= E; ++k)
            for (int j = 1; j <= E; ++j)
                for (int i = 1; i <= E; ++i, e += g.words) {
                    const int c = (k * N + j) * N + i;
                    if constexpr (std::is_same_v<T, float>) {
                        g.values[size_t(e)] = around[c + 1] - around[c - 1];
                        g.values[size_t(e) + 1] = around[c + N] - around[c - N];
                        g.values[size_t(e) + 2] = around[c + N * N] - around[c - N * N];
                    } else {
                        GradientBricks::pack<sizeof(T)>(
                            int(around[c + 1]) - int(around[c - 1]), int(around[c + N]) - int(around[c - N]),
                            int(around[c + N * N]) - int(around[c - N * N]), g.entries.data() + e);
                    }
                }
    });
}
}  // namespace

GradientBricks GradientBricks::build(const BrickedVolume& v, const std::vector<uint8_t>& brickShown,
                                     uint64_t maxBytes) {
    using BV = BrickedVolume;
    GradientBricks g;
    const size_t nb = v.brickCount();
    if (brickShown.size() != nb) return g;
    const int words = v.storage == Storage::F32 ? 3 : storageBytes(v.storage);
    // brick 0 (zeros) and the shown ones
    const uint64_t bricks =
        1 + uint64_t(std::count_if(brickShown.begin(), brickShown.end(), [](uint8_t s) { return s; }));
    const uint64_t count = bricks * uint64_t(BV::kBrick * words);
    if (count * 4 > maxBytes || count + 64 > uint64_t(std::numeric_limits<int32_t>::max())) return g;
    g.start.assign(nb, 0);
    int32_t next = BV::kBrick * words;
    for (size_t b = 0; b < nb; ++b)
        if (brickShown[b]) g.start[b] = std::exchange(next, next + BV::kBrick * words);
    g.words = words;
    // + 64: wide gathers may read past the last entry; on huge pages (4 KiB page faults
    // took most of the build)
    if (words == 3) {
        resizeHugePages(g.values, size_t(count) + 64);
        fill<float>(v, brickShown, g);
    } else {
        resizeHugePages(g.entries, size_t(count) + 64);
        if (words == 1)
            fill<uint8_t>(v, brickShown, g);
        else
            fill<uint16_t>(v, brickShown, g);
    }
    return g;
}

}  // namespace rtfact::volume
