#include "volume/macrocell_grid.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

namespace rtfact::volume {

namespace {
template <class T>
void minmax(const VolumeGrid& g, MacrocellGrid& m) {
    const T* d = g.data<T>();
    const int B = MacrocellGrid::kCell;
    tbb::parallel_for(0, m.n[2], [&](int cz) {
        for (int cy = 0; cy < m.n[1]; ++cy)
            for (int cx = 0; cx < m.n[0]; ++cx) {
                float lo = std::numeric_limits<float>::infinity(), hi = -lo;
                const int x1 = std::min(g.dims[0] - 1, (cx + 1) * B), y1 = std::min(g.dims[1] - 1, (cy + 1) * B),
                          z1 = std::min(g.dims[2] - 1, (cz + 1) * B);
                for (int z = cz * B; z <= z1; ++z)
                    for (int y = cy * B; y <= y1; ++y) {
                        const T* row = d + g.index(0, y, z);
                        for (int x = cx * B; x <= x1; ++x) {
                            const float v = float(row[x]);
                            lo = std::min(lo, v);
                            hi = std::max(hi, v);
                        }
                    }
                const size_t i = m.index(cx, cy, cz);
                m.lo[i] = lo;
                m.hi[i] = hi;
            }
    });
}
}  // namespace

MacrocellGrid buildMacrocells(const VolumeGrid& g) {
    MacrocellGrid m;
    for (int a = 0; a < 3; ++a) m.n[a] = std::max(1, (g.dims[a] - 1 + MacrocellGrid::kCell - 1) / MacrocellGrid::kCell);
    m.lo.resize(m.count());
    m.hi.resize(m.count());
    switch (g.storage) {
        case Storage::U8: minmax<uint8_t>(g, m); break;
        case Storage::U16: minmax<uint16_t>(g, m); break;
        default: minmax<float>(g, m); break;
    }
    return m;
}

}  // namespace rtfact::volume
