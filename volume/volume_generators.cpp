#include "volume/volume_generators.h"

#include <tbb/parallel_for.h>

#include <cmath>

#include "core/util/error.h"
#include "volume/volume_io.h"

namespace rtfact::volume {

namespace {
struct Ellipsoid {
    float a, rx, ry, rz, cx, cy, cz, phiDeg;
};
// Kak & Slaney's 3D Shepp-Logan ellipsoids (rotation about z only), with the higher
// contrast of the "modified" phantom so that the inner structures are visible.
const Ellipsoid kPhantom[] = {
    {1.0f, 0.69f, 0.92f, 0.81f, 0.0f, 0.0f, 0.0f, 0.0f},
    {-0.8f, 0.6624f, 0.874f, 0.78f, 0.0f, -0.0184f, 0.0f, 0.0f},
    {-0.2f, 0.11f, 0.31f, 0.22f, 0.22f, 0.0f, 0.0f, -18.0f},
    {-0.2f, 0.16f, 0.41f, 0.28f, -0.22f, 0.0f, 0.0f, 18.0f},
    {0.1f, 0.21f, 0.25f, 0.41f, 0.0f, 0.35f, -0.15f, 0.0f},
    {0.1f, 0.046f, 0.046f, 0.05f, 0.0f, 0.1f, 0.25f, 0.0f},
    {0.1f, 0.046f, 0.046f, 0.05f, 0.0f, -0.1f, 0.25f, 0.0f},
    {0.1f, 0.046f, 0.023f, 0.05f, -0.08f, -0.605f, 0.0f, 0.0f},
    {0.1f, 0.023f, 0.023f, 0.02f, 0.0f, -0.606f, 0.0f, 0.0f},
    {0.1f, 0.023f, 0.046f, 0.02f, 0.06f, -0.605f, 0.0f, 0.0f},
};
}  // namespace

VolumeGrid makeSheppLogan(int n, Storage storage) {
    const int64_t d[3] = {n, n, n};
    checkedVoxelCount("phantom", d);
    if (n < 2) throw Error("phantom", "size must be at least 2");
    VolumeGrid g;
    g.dims[0] = g.dims[1] = g.dims[2] = n;
    g.sourceType = storage == Storage::U8 ? "u8" : "u16";
    g.allocate(storage == Storage::U8 ? Storage::U8 : Storage::U16);
    const float q = storage == Storage::U8 ? 255.0f : 4095.0f;
    g.scale = 1.0f / q;
    tbb::parallel_for(0, n, [&](int k) {
        const float z = -1.0f + 2.0f * float(k) / float(n - 1);
        for (int j = 0; j < n; ++j) {
            const float y = -1.0f + 2.0f * float(j) / float(n - 1);
            for (int i = 0; i < n; ++i) {
                const float x = -1.0f + 2.0f * float(i) / float(n - 1);
                float v = 0.0f;
                for (const Ellipsoid& e : kPhantom) {
                    const float ph = e.phiDeg * 3.14159265f / 180.0f, c = std::cos(ph), s = std::sin(ph);
                    const float px = x - e.cx, py = y - e.cy, pz = z - e.cz;
                    const float u = (c * px + s * py) / e.rx, w = (-s * px + c * py) / e.ry, h = pz / e.rz;
                    if (u * u + w * w + h * h <= 1.0f) v += e.a;
                }
                const float st = std::round(std::clamp(v, 0.0f, 1.0f) * q);
                if (storage == Storage::U8)
                    g.bytes[g.index(i, j, k)] = uint8_t(st);
                else
                    g.data<uint16_t>()[g.index(i, j, k)] = uint16_t(st);
            }
        }
    });
    return g;
}

VolumeGrid makeSlab(int nx, int ny, int nz, int z0, int z1, uint8_t inside) {
    const int64_t d[3] = {nx, ny, nz};
    checkedVoxelCount("slab", d);
    VolumeGrid g;
    g.dims[0] = nx;
    g.dims[1] = ny;
    g.dims[2] = nz;
    g.sourceType = "u8";
    g.allocate(Storage::U8);
    for (int k = std::max(0, z0); k <= std::min(nz - 1, z1); ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) g.bytes[g.index(i, j, k)] = inside;
    return g;
}

}  // namespace rtfact::volume
