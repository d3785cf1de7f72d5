// Ambient occlusion for any GeometryScene: colour times the fraction of cosine-weighted
// hemisphere rays (deterministic per pixel and sample) that escape within `distance`.
#pragma once
#include <cmath>

#include "core/concepts/integrator.h"
#include "core/concepts/scene.h"
#include "core/render/random.h"

namespace rtfact::points {

struct AOIntegrator {
    Vec3f background{0.05f, 0.05f, 0.07f};
    int samples = 8;
    float distance = 0.0f;  // 0: 20% of the scene's bounding-box diagonal
    float offset = 4e-3f;   // ray start offset, in units of the diagonal

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
        const float diag = std::max(length(scene.bounds().extent()), 1e-6f);
        const float dist = distance > 0 ? distance : 0.2f * diag;
        Packet<N> open(0.0f);
        for (int s = 0; s < samples; ++s) {
            const Packet<N> u1 = hashToUnit<N>(ps.px, ps.py, uint32_t(ps.sample * samples + s), 11);
            const Packet<N> u2 = hashToUnit<N>(ps.px, ps.py, uint32_t(ps.sample * samples + s), 12);
            RayPacket<N> ao;
            for (int i = 0; i < N; ++i) {
                const Vec3f n = sp.n.lane(i);
                const Vec3f a = std::fabs(n.x) > 0.5f ? Vec3f(0, 1, 0) : Vec3f(1, 0, 0);
                const Vec3f t = normalize(cross(a, n)), b = cross(n, t);
                const float rr = std::sqrt(u1[i]), phi = 6.2831853f * u2[i];
                const Vec3f d = t * (rr * std::cos(phi)) + b * (rr * std::sin(phi)) + n * std::sqrt(std::max(0.0f, 1.0f - u1[i]));
                ao.dir.setLane(i, d);
            }
            // Splats overlap their neighbours: start AO rays clear of the local surface.
            ao.org = sp.p + sp.ng * Packet<N>(offset * diag);
            ao.tMin = Packet<N>(offset * diag);
            ao.tMax = Packet<N>(dist);
            ao.commonOrigin = false;
            ao.finalize();
            const Mask<N> occ = scene.template occluded<N>(ao, found);
            open = select(andNot(found, occ), open + Packet<N>(1.0f), open);
        }
        const Packet<N> vis = open * Packet<N>(1.0f / float(std::max(samples, 1)));
        r.color = select(found, sp.color * vis, r.color);
        r.alpha = select(found, Packet<N>(1.0f), r.alpha);
        return r;
    }
};

}  // namespace rtfact::points
