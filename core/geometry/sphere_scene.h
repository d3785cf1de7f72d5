// A scene of coloured spheres: the demo scene of `rtfact spheres` and the test scene
// of the core.
#pragma once
#include <vector>

#include "core/accel/bvh_intersector.h"
#include "core/accel/sah_bvh_builder.h"
#include "core/concepts/scene.h"
#include "core/geometry/sphere.h"
#include "core/render/tracer.h"

namespace rtfact {

struct SphereScene {
    std::vector<Sphere> spheres;
    std::vector<Vec3f> colors;
    BVH<Sphere> bvh;
    Tracer<BVHIntersector<SphereIntersector>> tracer;
    template <int N>
    using Hit = SphereIntersector::Hit<N>;

    void build(const SAHBVHBuilder& builder = SAHBVHBuilder{2}) {
        bvh = buildBVH<Sphere>(builder, std::span<const Sphere>(spheres));
    }
    AABB bounds() const { return bvh.bounds(); }

    template <int N>
    Hit<N> intersect(const RayPacket<N>& rays, const Mask<N>& active) const {
        return tracer.intersect(bvh, rays, active);
    }
    template <int N>
    Mask<N> occluded(const RayPacket<N>& rays, const Mask<N>& active) const {
        return tracer.occluded(bvh, rays, active);
    }
    template <int N>
    SurfacePoint<N> surface(const RayPacket<N>& rays, const Hit<N>& hit, const Mask<N>& valid) const {
        SurfacePoint<N> sp;
        sp.p = rays.org + rays.dir * hit.t;
        Vec3<N> c(Vec3f(0.0f)), col(Vec3f(1.0f));
        Packet<N> r(1.0f);
        for (int i = 0; i < N; ++i) {
            if (!valid[i]) continue;
            const int id = hit.id[i];
            c.setLane(i, spheres[id].center);
            r[i] = spheres[id].radius;
            col.setLane(i, colors.empty() ? Vec3f(1.0f) : colors[id]);
        }
        Vec3<N> n = (sp.p - c) * rcp(r);
        const Mask<N> back = dot(n, rays.dir) > Packet<N>(0.0f);
        n = select(back, -n, n);
        sp.n = n;
        sp.ng = n;
        sp.u = Packet<N>(0.0f);
        sp.v = Packet<N>(0.0f);
        sp.color = col;
        sp.material = Packet<N, int32_t>(0);
        return sp;
    }

    // The demo: a ground sphere and a grid of randomly sized and coloured spheres.
    static SphereScene demo(int count = 400, uint32_t seed = 7) {
        SphereScene s;
        uint32_t state = seed * 747796405u + 2891336453u;
        auto rnd = [&state] {
            state = state * 1664525u + 1013904223u;
            return float(state >> 8) * (1.0f / 16777216.0f);
        };
        s.spheres.push_back({{0.0f, -1000.0f, 0.0f}, 1000.0f});
        s.colors.push_back({0.75f, 0.75f, 0.72f});
        const int side = std::max(1, int(std::sqrt(float(count))));
        for (int i = 0; i < count; ++i) {
            const float gx = float(i % side) - 0.5f * float(side - 1);
            const float gz = float(i / side) - 0.5f * float(side - 1);
            const float r = 0.15f + 0.3f * rnd();
            s.spheres.push_back({{gx + 0.5f * (rnd() - 0.5f), r, gz + 0.5f * (rnd() - 0.5f)}, r});
            s.colors.push_back({0.2f + 0.8f * rnd(), 0.2f + 0.8f * rnd(), 0.2f + 0.8f * rnd()});
        }
        s.build();
        return s;
    }
};
static_assert(GeometryScene<SphereScene>);

}  // namespace rtfact

// The sphere scene is the core's own model of the generic pieces above it.
#include "core/accel/kdtree_intersector.h"
#include "core/concepts/integrator.h"
#include "core/concepts/renderer.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "core/render/framebuffer.h"
#include "core/render/jittered_sampler.h"
#include "core/render/pinhole_camera.h"
#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"

namespace rtfact {
static_assert(Intersector<BVHIntersector<SphereIntersector>, BVH<Sphere>>);
static_assert(Intersector<KdTreeIntersector<SphereIntersector>, KdTree<Sphere>>);
static_assert(Integrator<EyeLightIntegrator, SphereScene>);
static_assert(Integrator<DirectLightIntegrator, SphereScene>);
static_assert(
    Renderer<RayTracingRenderer<PixelCenterSampler, EyeLightIntegrator>, SphereScene, PinholeCamera, RGBAFramebuffer>);
static_assert(
    Renderer<RayTracingRenderer<JitteredSampler, DirectLightIntegrator>, SphereScene, PinholeCamera, RGBAFramebuffer>);
}  // namespace rtfact
