// Disc: one splat (centre, radius, octahedral-quantised normal, RGBA8 colour) in 24
// bytes, so that the cloud plus its LoD tree stays under 40 bytes per point. The alpha
// byte carries the LoD level (0 for input points, subtree height for representatives).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/concepts/primitive.h"

namespace rtfact::points {

// Octahedral normal encoding in 2 x 16 bits (max error ~0.005 degrees).
inline uint32_t encodeNormal(Vec3f n) {
    const float s = std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
    if (!(s > 0)) return encodeNormal({0, 0, 1});
    float u = n.x / s, v = n.y / s;
    if (n.z < 0) {
        const float ou = u, ov = v;
        u = (1.0f - std::fabs(ov)) * (ou >= 0 ? 1.0f : -1.0f);
        v = (1.0f - std::fabs(ou)) * (ov >= 0 ? 1.0f : -1.0f);
    }
    auto q = [](float x) { return uint32_t(std::lround((std::clamp(x, -1.0f, 1.0f) * 0.5f + 0.5f) * 65535.0f)); };
    return q(u) | (q(v) << 16);
}
inline Vec3f decodeNormal(uint32_t e) {
    const float u = float(e & 0xffffu) * (2.0f / 65535.0f) - 1.0f;
    const float v = float(e >> 16) * (2.0f / 65535.0f) - 1.0f;
    Vec3f n(u, v, 1.0f - std::fabs(u) - std::fabs(v));
    if (n.z < 0) {
        n.x = (1.0f - std::fabs(v)) * (u >= 0 ? 1.0f : -1.0f);
        n.y = (1.0f - std::fabs(u)) * (v >= 0 ? 1.0f : -1.0f);
    }
    return normalize(n);
}
inline uint32_t packRGBA(Vec3f c, uint8_t a) {
    auto b = [](float x) { return uint32_t(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f)); };
    return b(c.x) | (b(c.y) << 8) | (b(c.z) << 16) | (uint32_t(a) << 24);
}
inline Vec3f unpackRGB(uint32_t c) {
    return Vec3f(float(c & 255u), float((c >> 8) & 255u), float((c >> 16) & 255u)) * (1.0f / 255.0f);
}

// How far a disc of radius r whose unit normal has component na along an axis reaches
// along it: r sqrt(1 - na^2), padded by r / 1000 so that the box surely contains the disc
// whatever the normal's quantisation. Disc::bounds per axis, and the wide LoD BVH's leaf
// bounds for a block of discs at once (T a SIMD packet).
template <class T>
inline T discReach(T r, T na) {
    using std::max;
    using std::sqrt;
    return r * sqrt(max(T(0.0f), T(1.0f) - na * na)) + r * T(1e-3f);
}

struct Disc {
    Vec3f center;
    float radius = 0;
    uint32_t normal = 0;  // octahedral
    uint32_t rgba = 0;    // colour, alpha = LoD level

    Vec3f n() const { return decodeNormal(normal); }
    uint8_t level() const { return uint8_t(rgba >> 24); }
    // Tight box of a disc (discReach along each axis).
    AABB bounds() const { return bounds(center, radius, n()); }
    static AABB bounds(Vec3f center, float radius, Vec3f nn) {
        const Vec3f pad(discReach(radius, nn.x), discReach(radius, nn.y), discReach(radius, nn.z));
        return {center - pad, center + pad};
    }
};
static_assert(sizeof(Disc) == 24);
static_assert(Primitive<Disc>);

}  // namespace rtfact::points
