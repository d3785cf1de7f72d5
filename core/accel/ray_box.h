// Slab tests of one native chunk of a packet against a box, and the interval-arithmetic
// test of a whole coherent packet (its "frustum") against a box.
#pragma once
#include "core/math/aabb.h"
#include "core/ray/ray_packet.h"

namespace rtfact {

// Entry/exit distances of chunk k against [lo, hi], clipped to [tMin, tFar].
template <bool CommonOrigin, int N>
RTFACT_INLINE Mask<Packet<N>::W> chunkHitsBox(const Vec3f& lo, const Vec3f& hi, const RayPacket<N>& rays,
                                              const Packet<N>& tFar, int k, Packet<Packet<N>::W>* entryOut = nullptr) {
    using P = Packet<Packet<N>::W>;
    P tn[3], tf[3];
    for (int a = 0; a < 3; ++a) {
        const P& inv = rays.invDir[a].chunk(k);
        P t0, t1;
        if constexpr (CommonOrigin) {
            const float o = rays.org[a][0];
            t0 = P(lo[a] - o) * inv;
            t1 = P(hi[a] - o) * inv;
        } else {
            const P& o = rays.org[a].chunk(k);
            t0 = (P(lo[a]) - o) * inv;
            t1 = (P(hi[a]) - o) * inv;
        }
        tn[a] = min(t0, t1);
        tf[a] = max(t0, t1);
    }
    const P entry = max(max(tn[0], tn[1]), max(tn[2], rays.tMin.chunk(k)));
    const P exit = min(min(tf[0], tf[1]), min(tf[2], tFar.chunk(k)));
    if (entryOut) *entryOut = entry;
    return entry <= exit;
}

// The same test for packets whose active rays share direction signs (neg[a]: negative
// along axis a): the near and far planes are known, so no min/max per axis is needed.
// Inactive lanes (tFar = -inf) still fail whatever their signs.
template <bool CommonOrigin, int N>
RTFACT_INLINE Mask<Packet<N>::W> chunkHitsBoxSigned(const Vec3f& lo, const Vec3f& hi, const RayPacket<N>& rays,
                                                    const Packet<N>& tFar, int k, const bool neg[3]) {
    using P = Packet<Packet<N>::W>;
    P tn[3], tf[3];
    for (int a = 0; a < 3; ++a) {
        const P& inv = rays.invDir[a].chunk(k);
        const float nearP = neg[a] ? hi[a] : lo[a], farP = neg[a] ? lo[a] : hi[a];
        if constexpr (CommonOrigin) {
            const float o = rays.org[a][0];
            tn[a] = P(nearP - o) * inv;
            tf[a] = P(farP - o) * inv;
        } else {
            const P& o = rays.org[a].chunk(k);
            tn[a] = (P(nearP) - o) * inv;
            tf[a] = (P(farP) - o) * inv;
        }
    }
    const P entry = max(max(tn[0], tn[1]), max(tn[2], rays.tMin.chunk(k)));
    const P exit = min(min(tf[0], tf[1]), min(tf[2], tFar.chunk(k)));
    return entry <= exit;
}

// True when no ray of the packet can hit the box: the latest possible entry over the
// axes comes after the earliest possible exit. Needs uniform direction signs.
inline bool packetMissesBox(const Vec3f& lo, const Vec3f& hi, const PacketBounds& pb, float tFarHi) {
    float entryLo = pb.tMinLo, exitHi = tFarHi;
    for (int a = 0; a < 3; ++a) {
        const bool pos = pb.invDirLo[a] > 0.0f;
        const float nearP = pos ? lo[a] : hi[a], farP = pos ? hi[a] : lo[a];
        const float n0 = (nearP - pb.orgLo[a]), n1 = (nearP - pb.orgHi[a]);
        const float f0 = (farP - pb.orgLo[a]), f1 = (farP - pb.orgHi[a]);
        const float iL = pb.invDirLo[a], iH = pb.invDirHi[a];
        entryLo = std::max(entryLo, std::min(std::min(n0 * iL, n0 * iH), std::min(n1 * iL, n1 * iH)));
        exitHi = std::min(exitHi, std::max(std::max(f0 * iL, f0 * iH), std::max(f1 * iL, f1 * iH)));
    }
    return entryLo > exitHi;
}

}  // namespace rtfact
