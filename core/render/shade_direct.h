// Direct light at Lambertian shading points, shared by the direct-light and Whitted
// integrators: one shadow packet per light for all lanes of a packet, or a headlight at
// the viewer (which never casts visible shadows) when there are no lights.
#pragma once
#include <algorithm>

#include "core/concepts/scene.h"
#include "core/render/light_list.h"
#include "core/render/materials/lambert_material.h"

namespace rtfact {

// Shadow rays start this far off the surface: a fraction of the scene's size.
template <GeometryScene Scene>
float surfaceEpsilon(const Scene& scene) {
    return 1e-4f * std::max(length(scene.bounds().extent()), 1e-6f);
}

// Adds the light reaching `lanes` of `sp` (hit by `rays` at distance hitT) to `sum`.
template <int N, GeometryScene Scene>
Vec3<N> shadeDirect(const Scene& scene, const LightList& lights, bool shadows, const RayPacket<N>& rays,
                    const Packet<N>& hitT, const SurfacePoint<N>& sp, const Mask<N>& lanes, Vec3<N> sum) {
    using P = Packet<N>;
    const P zero(0.0f);
    const float eps = surfaceEpsilon(scene);
    const Vec3<N> wo = -rays.dir;
    auto shade = [&](const LightSample<N>& ls, bool castShadows) {
        Mask<N> lit = lanes & (dot(sp.n, ls.wi) > zero) & (dot(sp.ng, ls.wi) > zero);
        if (none(lit)) return;
        if (castShadows) {
            RayPacket<N> sh;
            sh.org = sp.p + sp.ng * P(eps);
            sh.dir = ls.wi;
            sh.tMin = zero;
            sh.tMax = ls.distance * P(1.0f - 1e-4f);
            sh.commonOrigin = false;
            sh.finalize();
            lit = andNot(lit, scene.template occluded<N>(sh, lit));
        }
        sum = select(lit, sum + LambertMaterial{}.eval<N>(sp, wo, ls.wi) * ls.radiance, sum);
    };
    if (lights.empty()) {
        LightSample<N> ls;
        ls.wi = wo;
        ls.distance = hitT;
        ls.radiance = Vec3<N>(Vec3f(3.14159265f));
        shade(ls, false);
    } else {
        for (const AnyLight& l : lights) shade(sampleLight<N>(l, sp.p, zero, zero), shadows);
    }
    return sum;
}

}  // namespace rtfact
