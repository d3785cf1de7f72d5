// Whitted-style ray tracing for mesh scenes: diffuse surfaces get direct light from
// the scene's lights with shadow rays (plus ambient), mirrors reflect, glass reflects
// and refracts (Fresnel-weighted), up to a depth limit. The reflected and refracted
// rays of all lanes of a packet are traced together as packets.
#pragma once
#include <cmath>

#include "core/render/light_list.h"
#include "surfaces/path_integrator.h"

namespace rtfact {

struct WhittedIntegrator {
    Vec3f background{0.05f, 0.05f, 0.07f};
    LightList lights;  // empty: a headlight at the camera
    float ambient = 0.08f;
    int maxDepth = 5;
    std::vector<PathMaterial> materials;  // by material id; empty: Lambert everywhere

    template <int N, class Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& rays, const Mask<N>& active, const PixelSample<N>&) const {
        Radiance<N> r;
        r.alpha = Packet<N>(1.0f);
        r.depth = Packet<N>(kInfinity);
        r.color = trace<N>(scene, rays, active, 0, &r.depth);
        return r;
    }

   private:
    template <int N, class Scene>
    Vec3<N> trace(const Scene& scene, const RayPacket<N>& rays, const Mask<N>& active, int depth,
                  Packet<N>* firstT) const {
        using P = Packet<N>;
        const P zero(0.0f);
        const auto hit = scene.template intersect<N>(rays, active);
        const Mask<N> found = active & (hit.id != Packet<N, int32_t>(-1));
        if (firstT) *firstT = select(found, hit.t, *firstT);
        Vec3<N> color(background);
        if (none(found)) return color;
        const SurfacePoint<N> sp = scene.template surface<N>(rays, hit, found);
        const float eps = 1e-4f * std::max(length(scene.bounds().extent()), 1e-6f);
        // Classify lanes by material and prepare the secondary directions.
        Mask<N> diffuse(false), specular(false), refract(false);
        Vec3<N> reflDir(Vec3f(0.0f)), refrDir(Vec3f(0.0f)), reflW(Vec3f(0.0f)), refrW(Vec3f(0.0f));
        static const PathMaterial kDefault{};
        BitMask<N>(found).forEach([&](int i) {
            const int32_t mid = sp.material[i];
            const PathMaterial& m =
                materials.empty() || mid < 0 || size_t(mid) >= materials.size() ? kDefault : materials[size_t(mid)];
            const Vec3f d = rays.dir.lane(i), n = sp.n.lane(i);
            const float cosi = -dot(d, n);
            if (m.kind == PathMaterial::Lambert) {
                diffuse.set(i, true);
                return;
            }
            specular.set(i, true);
            reflDir.setLane(i, d + n * (2.0f * cosi));
            if (m.kind == PathMaterial::Mirror) {
                reflW.setLane(i, m.albedo);
                return;
            }
            const uint32_t t = uint32_t(hit.id[i]);
            const Mesh& mesh = *scene.mesh;
            const Vec3f a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                        c = mesh.positions[mesh.indices[3 * t + 2]];
            const bool inside = dot(cross(b - a, c - a), d) > 0.0f;
            const float eta = inside ? m.ior : 1.0f / m.ior;
            const float k = 1.0f - eta * eta * (1.0f - cosi * cosi);
            float fr = 1.0f;
            if (k > 0.0f) {
                const float r0 = (1.0f - m.ior) / (1.0f + m.ior);
                const float cosx = inside ? std::sqrt(k) : cosi;
                fr = r0 * r0 + (1.0f - r0 * r0) * std::pow(1.0f - cosx, 5.0f);
                refract.set(i, true);
                refrDir.setLane(i, normalize(d * eta + n * (eta * cosi - std::sqrt(k))));
                refrW.setLane(i, m.albedo * (1.0f - fr));
            }
            reflW.setLane(i, m.albedo * fr);
        });
        // Diffuse: direct light with one shadow packet per light.
        Vec3<N> sum = sp.color * P(ambient);
        if (any(diffuse)) {
            auto shade = [&](const LightSample<N>& ls, bool castShadows) {
                const P cosT = dot(sp.n, ls.wi);
                Mask<N> lit = diffuse & (cosT > zero) & (dot(sp.ng, ls.wi) > zero);
                if (none(lit)) return;
                if (castShadows) {
                    RayPacket<N> sh;
                    sh.org = sp.p + sp.ng * P(eps);
                    sh.dir = ls.wi;
                    sh.tMin = zero;
                    sh.tMax = ls.distance * P(1.0f - 1e-4f);
                    sh.finalize();
                    lit = andNot(lit, scene.template occluded<N>(sh, lit));
                }
                sum = select(lit, sum + sp.color * ls.radiance * (cosT * P(1.0f / 3.14159265f)), sum);
            };
            if (lights.empty()) {
                LightSample<N> ls;
                ls.wi = -rays.dir;
                ls.distance = hit.t;
                ls.radiance = Vec3<N>(Vec3f(3.14159265f));
                shade(ls, false);
            } else {
                for (const AnyLight& l : lights) shade(sampleLight<N>(l, sp.p, zero, zero), true);
            }
            color = select(diffuse, sum, color);
        }
        if (any(specular)) {
            Vec3<N> spec(Vec3f(0.0f));
            if (depth + 1 < maxDepth) {
                RayPacket<N> rr;
                rr.org = sp.p + sp.ng * P(eps);
                rr.dir = reflDir;
                rr.tMin = zero;
                rr.tMax = P(kInfinity);
                rr.finalize();
                spec = reflW * trace<N>(scene, rr, specular, depth + 1, nullptr);
                if (any(refract)) {
                    RayPacket<N> tr;
                    tr.org = sp.p - sp.ng * P(eps);
                    tr.dir = refrDir;
                    tr.tMin = zero;
                    tr.tMax = P(kInfinity);
                    tr.finalize();
                    spec = select(refract, spec + refrW * trace<N>(scene, tr, refract, depth + 1, nullptr), spec);
                }
            }
            color = select(specular, spec, color);
        }
        return color;
    }
};

}  // namespace rtfact
