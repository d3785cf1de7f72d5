// Spheres: the analytic primitive that proves the core's genericity (the same BVH,
// kd-tree, traversal and renderer serve them as serve triangles, discs and volumes).
#pragma once
#include "core/concepts/intersector.h"

namespace rtfact {

struct Sphere {
    Vec3f center;
    float radius = 1.0f;
    AABB bounds() const { return {center - Vec3f(radius), center + Vec3f(radius)}; }
};
static_assert(Primitive<Sphere>);

struct SphereIntersector {
    template <int N>
    struct Hit {
        Packet<N> t;
        Packet<N, int32_t> id;
    };

    template <HitData D, int N>
    RTFACT_INLINE void intersect(const Sphere& s, uint32_t id, const RayPacket<N>& rays, Hit<N>& hit,
                                 int firstChunk) const {
        using P = Packet<Packet<N>::W>;
        using PI = Packet<Packet<N>::W, int32_t>;
        const Vec3<Packet<N>::W> c(s.center);
        const P r2(s.radius * s.radius);
        for (int k = firstChunk; k < Packet<N>::C; ++k) {
            const auto o = rays.org.chunk(k), d = rays.dir.chunk(k);
            const auto oc = o - c;
            const P a = dot(d, d), b = dot(oc, d), cc = dot(oc, oc) - r2;
            const P disc = b * b - a * cc;
            const auto m0 = disc >= P(0.0f);
            if (none(m0)) continue;
            const P sq = sqrt(max(disc, P(0.0f)));
            const P inva = rcp(a);
            const P t0 = (-b - sq) * inva, t1 = (-b + sq) * inva;
            const P& tMin = rays.tMin.chunk(k);
            const P t = select(t0 > tMin, t0, t1);
            P& th = hit.t.chunk(k);
            const auto m = m0 & (t > tMin) & (t < th);
            th = select(m, t, th);
            hit.id.chunk(k) = select(m, PI(int32_t(id)), hit.id.chunk(k));
        }
    }
};
static_assert(ElementIntersector<SphereIntersector, Sphere>);

}  // namespace rtfact
