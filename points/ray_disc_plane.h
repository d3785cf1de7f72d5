// rayDiscPlane: one ray against L disc planes given structure-of-arrays (centre[axis][lane],
// unit normal[axis][lane]): the distance t along the ray to each plane and the squared
// distance from that plane point to the disc's centre. The disc blocks' hit test and the
// LoD wide traversal's representative test are this same arithmetic (DiscIntersector's).
#pragma once
#include "core/ray/ray_packet.h"
#include "core/simd/packet.h"

namespace rtfact::points {

template <int L>
struct RayDiscPlane {
    Packet<L> t;      // +-inf or NaN for rays parallel to the plane: every comparison fails
    Packet<L> dist2;  // |ray(t) - centre|^2
};

template <int L>
RTFACT_INLINE RayDiscPlane<L> rayDiscPlane(const float (&c)[3][L], const float (&n)[3][L], const RayPacket<1>& ray) {
    using P = Packet<L>;
    const P cx = P::load(c[0]) - P(ray.org.x[0]), cy = P::load(c[1]) - P(ray.org.y[0]),
            cz = P::load(c[2]) - P(ray.org.z[0]);
    const P nx = P::load(n[0]), ny = P::load(n[1]), nz = P::load(n[2]);
    const P dx(ray.dir.x[0]), dy(ray.dir.y[0]), dz(ray.dir.z[0]);
    const P num = cx * nx + cy * ny + cz * nz;
    const P den = dx * nx + dy * ny + dz * nz;
    RayDiscPlane<L> r;
    r.t = num / den;
    const P px = dx * r.t - cx, py = dy * r.t - cy, pz = dz * r.t - cz;
    r.dist2 = px * px + py * py + pz * pz;
    return r;
}

}  // namespace rtfact::points
