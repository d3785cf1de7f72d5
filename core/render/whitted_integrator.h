// Whitted-style ray tracing for any GeometryScene: diffuse surfaces get direct light
// from the scene's lights with shadow rays (plus ambient), mirrors reflect, glass
// reflects and refracts (Fresnel-weighted), up to a depth limit. The reflected and
// refracted rays of all lanes of a packet are traced together as packets.
#pragma once
#include <vector>

#include "core/concepts/integrator.h"
#include "core/concepts/scene.h"
#include "core/render/light_list.h"
#include "core/render/path_material.h"
#include "core/render/shade_direct.h"

namespace rtfact {

struct WhittedIntegrator {
    Vec3f background{0.05f, 0.05f, 0.07f};
    LightList lights;  // empty: a headlight at the camera
    float ambient = 0.08f;
    int maxDepth = 5;
    std::vector<PathMaterial> materials;  // by material id; empty: Lambert everywhere

    template <int N, GeometryScene Scene>
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
        const float eps = surfaceEpsilon(scene);
        // Classify lanes by material and prepare the secondary directions.
        Mask<N> diffuse(false), specular(false), refract(false);
        Vec3<N> reflDir(Vec3f(0.0f)), refrDir(Vec3f(0.0f)), reflW(Vec3f(0.0f)), refrW(Vec3f(0.0f));
        BitMask<N>(found).forEach([&](int i) {
            const PathMaterial& m = pathMaterialOf(materials, sp.material[i]);
            if (m.kind == PathMaterial::Lambert) {
                diffuse.set(i, true);
                return;
            }
            specular.set(i, true);
            const Vec3f d = rays.dir.lane(i), n = sp.n.lane(i);
            if (m.kind == PathMaterial::Mirror) {
                reflDir.setLane(i, MirrorMaterial::reflect(d, n));
                reflW.setLane(i, m.albedo);
                return;
            }
            // Glass: both lobes, weighted by the Fresnel term.
            const GlassMaterial::Lobes l = m.glass().lobes(d, n, sp.front[i]);
            reflDir.setLane(i, l.reflect);
            if (l.refracts) {
                refract.set(i, true);
                refrDir.setLane(i, l.refract);
                refrW.setLane(i, m.albedo * (1.0f - l.fresnel));
            }
            reflW.setLane(i, m.albedo * l.fresnel);
        });
        if (any(diffuse))
            color = select(diffuse,
                           shadeDirect<N>(scene, lights, true, rays, hit.t, sp, diffuse, sp.color * P(ambient)), color);
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
static_assert(Integrator<WhittedIntegrator, GeometrySceneArchetype>);

}  // namespace rtfact
