// Small procedural meshes for the surface tests (no files needed).
#pragma once
#include <cmath>
#include <cstdint>
#include <random>

#include "surfaces/mesh.h"

namespace rtfact::test {

using namespace rtfact::surfaces;

// A jittered height field over [-1,1]^2 (y up): closed under shared edges, every ray
// crossing it from above hits it.
inline Mesh heightField(int n, uint32_t seed = 1) {
    Mesh m;
    m.source = "heightfield";
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> j(-0.3f, 0.3f);
    for (int z = 0; z <= n; ++z)
        for (int x = 0; x <= n; ++x) {
            const float fx = -1.0f + 2.0f * float(x) / float(n), fz = -1.0f + 2.0f * float(z) / float(n);
            m.positions.push_back({fx, 0.2f * std::sin(3.0f * fx) * std::cos(2.0f * fz) + 0.1f * j(rng), fz});
        }
    auto v = [n](int x, int z) { return uint32_t(z * (n + 1) + x); };
    for (int z = 0; z < n; ++z)
        for (int x = 0; x < n; ++x) {
            // Alternate the diagonal so edges of every direction occur.
            if ((x + z) & 1) {
                m.indices.insert(m.indices.end(),
                                 {v(x, z), v(x + 1, z), v(x + 1, z + 1), v(x, z), v(x + 1, z + 1), v(x, z + 1)});
            } else {
                m.indices.insert(m.indices.end(),
                                 {v(x, z), v(x + 1, z), v(x, z + 1), v(x + 1, z), v(x + 1, z + 1), v(x, z + 1)});
            }
        }
    m.computeNormals();
    return m;
}

// Random triangles of mixed sizes in the unit cube (overlapping, a hard case for BVHs).
inline Mesh triangleSoup(int count, uint32_t seed = 2) {
    Mesh m;
    m.source = "soup";
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), s(0.01f, 0.3f);
    for (int i = 0; i < count; ++i) {
        const Vec3f c{u(rng), u(rng), u(rng)};
        const float r = s(rng);
        for (int k = 0; k < 3; ++k) m.positions.push_back(c + Vec3f(u(rng), u(rng), u(rng)) * r);
        m.indices.insert(m.indices.end(), {uint32_t(3 * i), uint32_t(3 * i + 1), uint32_t(3 * i + 2)});
    }
    m.computeNormals();
    return m;
}

// A closed UV sphere.
inline Mesh uvSphere(Vec3f c, float r, int seg) {
    Mesh m;
    m.source = "sphere";
    for (int i = 0; i <= seg; ++i)
        for (int j = 0; j < 2 * seg; ++j) {
            const float th = 3.14159265f * float(i) / float(seg), ph = 3.14159265f * float(j) / float(seg);
            m.positions.push_back(c +
                                  Vec3f(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)) * r);
        }
    auto v = [seg](int i, int j) { return uint32_t(i * 2 * seg + (j % (2 * seg))); };
    for (int i = 0; i < seg; ++i)
        for (int j = 0; j < 2 * seg; ++j) {
            if (i > 0) m.indices.insert(m.indices.end(), {v(i, j), v(i, j + 1), v(i + 1, j)});
            if (i < seg - 1) m.indices.insert(m.indices.end(), {v(i, j + 1), v(i + 1, j + 1), v(i + 1, j)});
        }
    m.computeNormals();
    return m;
}

}  // namespace rtfact::test
