// Direction sampling shared by integrators (AO, path tracing).
#pragma once
#include <cmath>

#include "core/simd/vec3.h"

namespace rtfact {

// An orthonormal frame around unit n (branchless, Duff et al.'s construction).
template <int N>
RTFACT_INLINE void orthonormalBasis(const Vec3<N>& n, Vec3<N>& t, Vec3<N>& b) {
    const Packet<N> one(1.0f), zero(0.0f);
    const Packet<N> sign = select(n.z < zero, Packet<N>(-1.0f), one);
    const Packet<N> a = Packet<N>(-1.0f) / (sign + n.z);
    const Packet<N> bb = n.x * n.y * a;
    t = Vec3<N>(one + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    b = Vec3<N>(bb, sign + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction around n from two uniform numbers.
template <int N>
RTFACT_INLINE Vec3<N> cosineHemisphere(const Vec3<N>& n, const Packet<N>& u1, const Packet<N>& u2) {
    Vec3<N> t, b;
    orthonormalBasis(n, t, b);
    const Packet<N> r = sqrt(u1);
    const Packet<N> phi = u2 * Packet<N>(6.28318531f);
    Packet<N> c, s;
    for (int i = 0; i < N; ++i) {
        c[i] = std::cos(phi[i]);
        s[i] = std::sin(phi[i]);
    }
    const Packet<N> z = sqrt(max(Packet<N>(0.0f), Packet<N>(1.0f) - u1));
    return t * (r * c) + b * (r * s) + n * z;
}

}  // namespace rtfact
