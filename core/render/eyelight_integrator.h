// Eye light: surfaces lit from the viewer, |cos| between normal and ray times colour.
// Generic over any GeometryScene (spheres, meshes, point clouds).
#pragma once
#include "core/concepts/integrator.h"
#include "core/concepts/scene.h"

namespace rtfact {

struct EyeLightIntegrator {
    Vec3f background{0.05f, 0.05f, 0.07f};

    template <int N, class Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& rays, const Mask<N>& active, const PixelSample<N>&) const {
        const auto hit = scene.template intersect<N>(rays, active);
        const Mask<N> found = active & (hit.id != Packet<N, int32_t>(-1));
        Radiance<N> r;
        r.color = Vec3<N>(background);
        r.alpha = Packet<N>(0.0f);
        r.depth = select(found, hit.t, Packet<N>(kInfinity));
        if (none(found)) return r;
        const SurfacePoint<N> sp = scene.template surface<N>(rays, hit, found);
        const Packet<N> c = abs(dot(sp.n, rays.dir));
        r.color = select(found, sp.color * c, r.color);
        r.alpha = select(found, Packet<N>(1.0f), r.alpha);
        return r;
    }
};

}  // namespace rtfact
