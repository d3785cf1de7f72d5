// Ambient occlusion: the fraction of a cosine-weighted hemisphere around each hit that
// is open within `radius`. The AO rays of all lanes of a packet go out together, one
// packet per sample direction, as occlusion queries. Their directions are random but
// their origins are neighbouring pixels and they are short, so packets still share
// nodes: measured faster than the wide single-ray path (rtfact mesh --integrator ao
// on the bunny, packet 64), hence the packet default.
#pragma once
#include <cmath>

#include "core/concepts/integrator.h"
#include "core/concepts/scene.h"
#include "core/render/random.h"
#include "surfaces/secondary_rays.h"

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

template <SecondaryRayPolicy Secondary = PacketSecondaryRays>
struct AOIntegratorT {
    Vec3f background{0.05f, 0.05f, 0.07f};
    int samples = 16;     // AO rays per hit
    float radius = 0.0f;  // 0: 20% of the scene diagonal

    template <int N, class Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& rays, const Mask<N>& active, const PixelSample<N>& ps) const {
        const auto hit = scene.template intersect<N>(rays, active);
        const Mask<N> found = active & (hit.id != Packet<N, int32_t>(-1));
        Radiance<N> r;
        r.color = Vec3<N>(background);
        r.alpha = Packet<N>(0.0f);
        r.depth = select(found, hit.t, Packet<N>(kInfinity));
        if (none(found)) return r;
        const SurfacePoint<N> sp = scene.template surface<N>(rays, hit, found);
        const AABB b = scene.bounds();
        const float diag = std::max(length(b.extent()), 1e-6f);
        const float rad = radius > 0.0f ? radius : 0.2f * diag;
        RayPacket<N> ao;
        ao.org = sp.p + sp.ng * Packet<N>(1e-4f * diag);
        ao.tMin = Packet<N>(0.0f);
        ao.tMax = Packet<N>(rad);
        ao.commonOrigin = false;
        Packet<N> open(0.0f);
        for (int s = 0; s < samples; ++s) {
            const uint32_t sample = uint32_t(ps.sample * samples + s);
            ao.dir = cosineHemisphere(sp.ng, hashToUnit(ps.px, ps.py, sample, 0), hashToUnit(ps.px, ps.py, sample, 1));
            ao.finalize();
            const Mask<N> occ = occludedSecondary<Secondary>(scene, ao, found);
            open = open + select(andNot(found, occ), Packet<N>(1.0f), Packet<N>(0.0f));
        }
        const Packet<N> f = open * Packet<N>(1.0f / float(std::max(samples, 1)));
        r.color = select(found, sp.color * f, r.color);
        r.alpha = select(found, Packet<N>(1.0f), r.alpha);
        return r;
    }
};
using AOIntegrator = AOIntegratorT<>;

}  // namespace rtfact
