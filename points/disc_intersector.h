// DiscIntersector: ray/disc test for chunks [firstChunk, C) of a packet; the same code
// serves single rays (W = 1) and any packet size. Hit: the plane of the disc within its
// radius, tMin < t < hit.t.
#pragma once
#include "core/concepts/intersector.h"
#include "core/simd/chunk_group.h"
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
            intersectDiscGroup<Packet<N>::W>(c, n, r2, id, rays, hit, k, Mask<Packet<N>::W>(true));
    }

    // Lanes `lanes` of native chunks k .. k + M / W - 1 of a packet only (M = W: chunk
    // k), the LoD wide traversal's chunks and lane groups.
    template <int M, int N>
    RTFACT_INLINE static void intersectDiscGroup(Vec3f c, Vec3f n, float r2, int32_t id, const RayPacket<N>& rays,
                                                 Hit<N>& hit, int k, const Mask<M>& lanes) {
        using P = Packet<M>;
        using PI = Packet<M, int32_t>;
        const P& ox = chunkGroup<M>(rays.org.x, k);
        const P& oy = chunkGroup<M>(rays.org.y, k);
        const P& oz = chunkGroup<M>(rays.org.z, k);
        const P& dx = chunkGroup<M>(rays.dir.x, k);
        const P& dy = chunkGroup<M>(rays.dir.y, k);
        const P& dz = chunkGroup<M>(rays.dir.z, k);
        const P cx = P(c.x) - ox, cy = P(c.y) - oy, cz = P(c.z) - oz;
        const P num = cx * P(n.x) + cy * P(n.y) + cz * P(n.z);
        const P den = dx * P(n.x) + dy * P(n.y) + dz * P(n.z);
        const P t = num / den;  // +-inf or NaN for parallel rays: every comparison below fails
        const P px = dx * t - cx, py = dy * t - cy, pz = dz * t - cz;
        const P dist2 = px * px + py * py + pz * pz;
        P& th = chunkGroup<M>(hit.t, k);
        PI& hid = chunkGroup<M>(hit.id, k);
        const auto m = lanes & (dist2 <= P(r2)) & (t > chunkGroup<M>(rays.tMin, k)) & (t < th);
        th = select(m, t, th);
        hid = select(m, PI(id), hid);
    }
};
static_assert(ElementIntersector<DiscIntersector, Disc>);

}  // namespace rtfact::points
