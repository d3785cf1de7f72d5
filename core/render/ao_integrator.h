// Ambient occlusion for any GeometryScene (meshes, point clouds, spheres): the fraction
// of a cosine-weighted hemisphere around each hit that is open within `radius`. The AO
// rays of all lanes of a packet go out together, one packet per sample direction, as
// occlusion queries. Their directions are random but
// their origins are neighbouring pixels and they are short, so packets still share
// nodes: measured faster than the wide single-ray path (rtfact mesh --integrator ao
// on the bunny, packet 64), hence the packet default.
#pragma once
#include <cmath>

#include "core/render/primary_hit.h"
#include "core/render/random.h"
#include "core/render/sampling.h"
#include "core/render/secondary_rays.h"

namespace rtfact {

template <SecondaryRayPolicy Secondary = PacketSecondaryRays>
struct AOIntegratorT {
    Vec3f background{0.05f, 0.05f, 0.07f};
    int samples = 16;     // AO rays per hit
    float radius = 0.0f;  // 0: 20% of the scene diagonal
    // Ray start, as fractions of the scene diagonal: pushed off the surface by `offset`
    // and ignoring hits closer than `minDistance` (overlapping splats need both).
    float offset = 1e-4f;
    float minDistance = 0.0f;

    template <int N, GeometryScene Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& rays, const Mask<N>& active, const PixelSample<N>& ps) const {
        PrimaryHit<N, Scene> ph;
        if (!tracePrimary(scene, rays, active, background, ph)) return ph.result;
        const SurfacePoint<N>& sp = ph.sp;
        const Mask<N>& found = ph.found;
        const AABB b = scene.bounds();
        const float diag = std::max(length(b.extent()), 1e-6f);
        const float rad = radius > 0.0f ? radius : 0.2f * diag;
        RayPacket<N> ao;
        ao.org = sp.p + sp.ng * Packet<N>(offset * diag);
        ao.tMin = Packet<N>(minDistance * diag);
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
        return ph.finish(sp.color * (open * Packet<N>(1.0f / float(std::max(samples, 1)))));
    }
};
static_assert(Integrator<AOIntegratorT<PacketSecondaryRays>, GeometrySceneArchetype> &&
              Integrator<AOIntegratorT<WideSecondaryRays>, GeometrySceneArchetype>);
using AOIntegrator = AOIntegratorT<>;

}  // namespace rtfact
