// Direct lighting with shadow rays: Lambertian surfaces (colour from the scene) lit by
// the scene's lights plus a small ambient term. All shadow rays of a packet towards
// one light travel together as a packet (core/render/shade_direct.h).
#pragma once
#include "core/render/light_list.h"
#include "core/render/primary_hit.h"
#include "core/render/shade_direct.h"

namespace rtfact {

struct DirectLightIntegrator {
    Vec3f background{0.05f, 0.05f, 0.07f};
    LightList lights;  // empty: a headlight at the camera
    float ambient = 0.08f;
    bool shadows = true;

    template <int N, GeometryScene Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& rays, const Mask<N>& active, const PixelSample<N>&) const {
        PrimaryHit<N, Scene> ph;
        if (!tracePrimary(scene, rays, active, background, ph)) return ph.result;
        const Vec3<N> sum =
            shadeDirect<N>(scene, lights, shadows, rays, ph.hit.t, ph.sp, ph.found, ph.sp.color * Packet<N>(ambient));
        return ph.finish(sum);
    }
};
static_assert(Integrator<DirectLightIntegrator, GeometrySceneArchetype>);

}  // namespace rtfact
