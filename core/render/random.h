// Stateless per-lane random numbers: a hash of (pixel x, pixel y, sample, dimension),
// so renders are identical for any thread count, tile order and packet size.
#pragma once
#include "core/simd/vec3.h"  // Packet in namespace rtfact

namespace rtfact {

template <int N>
RTFACT_INLINE Packet<N> hashToUnit(const Packet<N, int32_t>& x, const Packet<N, int32_t>& y, uint32_t sample,
                                   uint32_t dim) {
    constexpr int W = Packet<N>::W;
    using U = simd::nvec<uint32_t, W>;
    Packet<N> r;
    for (int k = 0; k < Packet<N>::C; ++k) {
        U h = (U)x.c[k] * 0x8da6b343u ^ (U)y.c[k] * 0xd8163841u;
        h ^= simd::splat<uint32_t, W>(sample * 0xcb1ab31fu + dim * 0x9e3779b9u);
        // PCG-style output permutation
        h = h * 747796405u + 2891336453u;
        h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
        h = (h >> 22u) ^ h;
        r.c[k] = simd::toFloat<W>((simd::nvec<int32_t, W>)(h >> 8)) * (1.0f / 16777216.0f);
    }
    return r;
}

}  // namespace rtfact
