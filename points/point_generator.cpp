#include "points/point_generator.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace rtfact::points {

PointCloud samplePointsOnMesh(const TriangleMesh& mesh, size_t count, uint64_t seed, float radiusFactor) {
    if (count == 0) throw Error("", "point count must be positive");
    const size_t nt = mesh.triangles.size();
    std::vector<double> cdf(nt + 1, 0.0);
    for (size_t i = 0; i < nt; ++i) {
        const auto& t = mesh.triangles[i];
        const Vec3f a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
        const double area = 0.5 * double(length(cross(b - a, c - a)));
        cdf[i + 1] = cdf[i] + (std::isfinite(area) ? area : 0.0);
    }
    const double total = cdf[nt];
    if (!(total > 0)) throw Error("", "mesh has zero area");
    PointCloud pc;
    pc.positions.resize(count);
    pc.normals.resize(count);
    const float radius = float(radiusFactor * std::sqrt(total / (double(count) * 3.14159265358979)));
    pc.radii.assign(count, radius);
    const size_t block = 1 << 16;
    tbb::parallel_for(size_t(0), (count + block - 1) / block, [&](size_t bi) {
        uint64_t s = (seed + 0x9e3779b97f4a7c15ull * (bi + 1)) | 1u;
        auto next = [&s] {  // xorshift64*
            s ^= s >> 12;
            s ^= s << 25;
            s ^= s >> 27;
            return double((s * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
        };
        for (size_t i = bi * block, e = std::min(count, (bi + 1) * block); i < e; ++i) {
            const double u = next() * total;
            size_t t = size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin());
            t = std::min(std::max<size_t>(t, 1), nt) - 1;
            const auto& tri = mesh.triangles[t];
            const Vec3f a = mesh.vertices[tri[0]], b = mesh.vertices[tri[1]], c = mesh.vertices[tri[2]];
            double r1 = next(), r2 = next();
            if (r1 + r2 > 1) r1 = 1 - r1, r2 = 1 - r2;
            pc.positions[i] = a + (b - a) * float(r1) + (c - a) * float(r2);
            pc.normals[i] = normalize(cross(b - a, c - a));
        }
    });
    pc.format = "generated";
    pc.properties = {"x", "y", "z", "nx", "ny", "nz", "radius"};
    return pc;
}

}  // namespace rtfact::points
