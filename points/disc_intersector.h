// DiscIntersector: ray/disc test for chunks [firstChunk, C) of a packet; the same code
// serves single rays (W = 1) and any packet size. Hit: the plane of the disc within its
// radius, tMin < t < hit.t.
#pragma once
#include "core/concepts/intersector.h"
#include "points/disc.h"

namespace rtfact::points {

struct DiscIntersector {
    template <int N>
    struct Hit {
        Packet<N> t;
        Packet<N, int32_t> id;  // >= 0: input disc (leaf order); <= -2: representative disc of inner node -id-2
    };

    template <HitData D, int N>
    RTFACT_INLINE void intersect(const Disc& d, uint32_t id, const RayPacket<N>& rays, Hit<N>& hit,
                                 int firstChunk) const {
        intersectDisc(d.center, d.n(), d.radius * d.radius, int32_t(id), rays, hit, firstChunk);
    }

    template <int N>
    RTFACT_INLINE static void intersectDisc(Vec3f c, Vec3f n, float r2, int32_t id, const RayPacket<N>& rays,
                                            Hit<N>& hit, int firstChunk) {
        for (int k = firstChunk; k < Packet<N>::C; ++k)
            intersectDiscChunk(c, n, r2, id, rays, hit, k, Mask<Packet<N>::W>(true));
    }

    // Lanes `lanes` of native chunk k only (the LoD wide traversal's chunks).
    template <int N>
    RTFACT_INLINE static void intersectDiscChunk(Vec3f c, Vec3f n, float r2, int32_t id, const RayPacket<N>& rays,
                                                 Hit<N>& hit, int k, const Mask<Packet<N>::W>& lanes) {
        constexpr int W = Packet<N>::W;
        using P = Packet<W>;
        using PI = Packet<W, int32_t>;
        const P ox = rays.org.x.chunk(k), oy = rays.org.y.chunk(k), oz = rays.org.z.chunk(k);
        const P dx = rays.dir.x.chunk(k), dy = rays.dir.y.chunk(k), dz = rays.dir.z.chunk(k);
        const P cx = P(c.x) - ox, cy = P(c.y) - oy, cz = P(c.z) - oz;
        const P num = cx * P(n.x) + cy * P(n.y) + cz * P(n.z);
        const P den = dx * P(n.x) + dy * P(n.y) + dz * P(n.z);
        const P t = num / den;  // +-inf or NaN for parallel rays: every comparison below fails
        const P px = dx * t - cx, py = dy * t - cy, pz = dz * t - cz;
        const P dist2 = px * px + py * py + pz * pz;
        P& th = hit.t.chunk(k);
        const auto m = lanes & (dist2 <= P(r2)) & (t > rays.tMin.chunk(k)) & (t < th);
        th = select(m, t, th);
        hit.id.chunk(k) = select(m, PI(id), hit.id.chunk(k));
    }
};
static_assert(ElementIntersector<DiscIntersector, Disc>);

}  // namespace rtfact::points
