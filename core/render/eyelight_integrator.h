// Eye light: surfaces lit from the viewer, |cos| between normal and ray times colour.
// Generic over any GeometryScene (spheres, meshes, point clouds).
#pragma once
#include "core/render/primary_hit.h"

namespace rtfact {

struct EyeLightIntegrator {
    Vec3f background{0.05f, 0.05f, 0.07f};

    template <int N, GeometryScene Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& rays, const Mask<N>& active, const PixelSample<N>&) const {
        PrimaryHit<N, Scene> ph;
        if (!tracePrimary(scene, rays, active, background, ph)) return ph.result;
        return ph.finish(ph.sp.color * abs(dot(ph.sp.n, rays.dir)));
    }
};
static_assert(Integrator<EyeLightIntegrator, GeometrySceneArchetype>);

}  // namespace rtfact
