// The first step of every surface integrator: nearest hits of the camera rays, the
// background where they miss, and shading data where they hit.
#pragma once
#include "core/concepts/integrator.h"
#include "core/concepts/scene.h"

namespace rtfact {

template <int N, class Scene>
struct PrimaryHit {
    typename Scene::template Hit<N> hit;
    Mask<N> found;       // lanes that hit something
    Radiance<N> result;  // background and depth filled in; colour of hit lanes to be set
    SurfacePoint<N> sp;  // valid in `found` lanes

    // Writes the colour of the hit lanes (opaque) into the result.
    Radiance<N> finish(const Vec3<N>& color) {
        result.color = select(found, color, result.color);
        result.alpha = select(found, Packet<N>(1.0f), result.alpha);
        return result;
    }
};

// Returns false (and a background-only result) when no lane hits.
template <int N, class Scene>
bool tracePrimary(const Scene& scene, const RayPacket<N>& rays, const Mask<N>& active, const Vec3f& background,
                  PrimaryHit<N, Scene>& out) {
    out.hit = scene.template intersect<N>(rays, active);
    out.found = active & (out.hit.id != Packet<N, int32_t>(-1));
    out.result.color = Vec3<N>(background);
    out.result.alpha = Packet<N>(0.0f);
    out.result.depth = select(out.found, out.hit.t, Packet<N>(kInfinity));
    if (none(out.found)) return false;
    out.sp = scene.template surface<N>(rays, out.hit, out.found);
    return true;
}

}  // namespace rtfact
