// Direct lighting with shadow rays: Lambertian surfaces (colour from the scene) lit by
// the scene's lights plus a small ambient term. All shadow rays of a packet towards
// one light travel together as a packet.
#pragma once
#include "core/render/light_list.h"
#include "core/render/primary_hit.h"

namespace rtfact {

struct DirectLightIntegrator {
    Vec3f background{0.05f, 0.05f, 0.07f};
    LightList lights;  // empty: a headlight at the camera
    float ambient = 0.08f;
    bool shadows = true;

    template <int N, class Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& rays, const Mask<N>& active, const PixelSample<N>&) const {
        PrimaryHit<N, Scene> ph;
        if (!tracePrimary(scene, rays, active, background, ph)) return ph.result;
        const SurfacePoint<N>& sp = ph.sp;
        const Mask<N>& found = ph.found;
        const AABB b = scene.bounds();
        const float eps = 1e-4f * std::max(length(b.extent()), 1e-6f);
        Vec3<N> sum = sp.color * Packet<N>(ambient);
        const Packet<N> zero(0.0f);
        auto shade = [&](const LightSample<N>& ls, bool castShadows) {
            const Packet<N> cosT = dot(sp.n, ls.wi);
            Mask<N> lit = found & (cosT > zero) & (dot(sp.ng, ls.wi) > zero);
            if (none(lit)) return;
            if (castShadows) {
                RayPacket<N> sh;
                sh.org = sp.p + sp.ng * Packet<N>(eps);
                sh.dir = ls.wi;
                sh.tMin = zero;
                sh.tMax = ls.distance * Packet<N>(1.0f - 1e-4f);
                sh.commonOrigin = false;
                sh.finalize();
                lit = andNot(lit, scene.template occluded<N>(sh, lit));
            }
            const Vec3<N> c = sp.color * ls.radiance * (cosT * Packet<N>(1.0f / 3.14159265f));
            sum = select(lit, sum + c, sum);
        };
        if (lights.empty()) {
            // Headlight: light from the viewer never casts visible shadows.
            LightSample<N> ls;
            ls.wi = -rays.dir;
            ls.distance = ph.hit.t;
            ls.radiance = Vec3<N>(Vec3f(3.14159265f));
            shade(ls, false);
        } else {
            for (const AnyLight& l : lights) shade(sampleLight<N>(l, sp.p, zero, zero), shadows);
        }
        return ph.finish(sum);
    }
};

}  // namespace rtfact
