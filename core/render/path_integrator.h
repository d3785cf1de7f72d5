// Progressive path tracer for any GeometryScene: Lambertian, perfect mirror and
// dielectric glass materials (PathMaterial per material id), emission as area lights,
// and a constant environment. All lanes of a packet bounce together, so secondary rays
// from different surfaces still travel as one (incoherent) packet; by default those
// bounces are traced one by one through the scene's wide BVH when it has one.
// Each --spp sample adds one path per pixel; the framebuffer averages them.
#pragma once
#include <algorithm>
#include <vector>

#include "core/concepts/integrator.h"
#include "core/concepts/scene.h"
#include "core/render/path_material.h"
#include "core/render/random.h"
#include "core/render/secondary_rays.h"
#include "core/render/shade_direct.h"

namespace rtfact {

template <SecondaryRayPolicy Secondary = WideSecondaryRays>
struct PathIntegratorT {
    Vec3f background{0.0f};  // constant environment radiance
    int maxDepth = 6;
    int rouletteDepth = 3;                // Russian roulette from this bounce on (unbiased)
    std::vector<PathMaterial> materials;  // by material id; empty: one default Lambert

    template <int N, GeometryScene Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& camRays, const Mask<N>& active, const PixelSample<N>& ps) const {
        using P = Packet<N>;
        const P zero(0.0f), one(1.0f);
        const float eps = surfaceEpsilon(scene);
        Radiance<N> out;
        out.alpha = P(1.0f);
        out.depth = P(kInfinity);
        Vec3<N> L(Vec3f(0.0f)), beta(Vec3f(1.0f));
        RayPacket<N> rays = camRays;
        Mask<N> alive = active;
        for (int depth = 0; depth < maxDepth && any(alive); ++depth) {
            // Camera rays are coherent packets; bounces are not.
            const auto hit = depth == 0 ? scene.template intersect<N>(rays, alive)
                                        : intersectSecondary<Secondary>(scene, rays, alive);
            const Mask<N> found = alive & (hit.id != Packet<N, int32_t>(-1));
            if (depth == 0) out.depth = select(found, hit.t, out.depth);
            // Escaped paths see the environment.
            L = select(andNot(alive, found), L + beta * Vec3<N>(background), L);
            alive = found;
            if (none(alive)) break;
            const SurfacePoint<N> sp = scene.template surface<N>(rays, hit, found);
            const uint32_t dim = 4 + 5 * uint32_t(depth);
            const P u1 = hashToUnit(ps.px, ps.py, uint32_t(ps.sample), dim);
            const P u2 = hashToUnit(ps.px, ps.py, uint32_t(ps.sample), dim + 1);
            const P u3 = hashToUnit(ps.px, ps.py, uint32_t(ps.sample), dim + 2);
            const P u4 = hashToUnit(ps.px, ps.py, uint32_t(ps.sample), dim + 3);
            Vec3<N> newDir(Vec3f(0.0f)), weight(Vec3f(0.0f)), emitted(Vec3f(0.0f));
            Mask<N> diffuse(false);
            Mask<N> below(false);  // continue on the far side of the surface
            BitMask<N>(found).forEach([&](int i) {
                const PathMaterial& m = pathMaterialOf(materials, sp.material[i]);
                const SurfacePoint<1> s = sp.lane(i);
                const Vec3<1> wo(-rays.dir.lane(i));
                emitted.setLane(i, m.emissive().template emitted<1>(s, wo).lane(0));
                if (m.kind == PathMaterial::Lambert) {
                    diffuse.set(i, true);  // sampled below in SIMD
                    return;
                }
                const BsdfSample<1> b = m.kind == PathMaterial::Mirror
                                            ? m.mirror().template sample<1>(s, wo, u3[i], u4[i])
                                            : m.glass().template sample<1>(s, wo, u3[i], u4[i]);
                weight.setLane(i, b.weight.lane(0));
                newDir.setLane(i, b.wi.lane(0));
                below.set(i, b.transmit[0]);
            });
            L = select(found, L + beta * emitted, L);
            // Lambert lanes: cosine-weighted directions; the scene's colour already holds
            // the material's kd (the default one for meshes without materials).
            if (any(diffuse)) {
                const BsdfSample<N> b = LambertMaterial{}.sample<N>(sp, -rays.dir, u1, u2);
                newDir = select(diffuse, b.wi, newDir);
                weight = select(diffuse, b.weight, weight);
            }
            // Directions below the geometric surface (shading-normal artefacts) end the path.
            const P side = dot(newDir, sp.ng);
            alive = found & select(below, side<zero, side> zero);
            beta = beta * weight;
            if (depth >= rouletteDepth) {
                const P q = min(P(0.95f), max(max(beta.x, beta.y), beta.z));
                const Mask<N> survive = u4 < q;
                alive = alive & survive;
                beta = beta * select(q > zero, one / q, one);
            }
            rays.org = sp.p + sp.ng * select(below, P(-eps), P(eps));
            rays.dir = normalize(newDir);
            rays.tMin = zero;
            rays.tMax = P(kInfinity);
            rays.commonOrigin = false;
            rays.finalize();
        }
        out.color = L;
        return out;
    }

    // One PathMaterial per material of a mesh (MTL-style data).
    template <class MeshLike>
    static std::vector<PathMaterial> fromMesh(const MeshLike& m) {
        return pathMaterials(m);
    }
};
static_assert(Integrator<PathIntegratorT<PacketSecondaryRays>, GeometrySceneArchetype> &&
              Integrator<PathIntegratorT<WideSecondaryRays>, GeometrySceneArchetype>);

using PathIntegrator = PathIntegratorT<>;

}  // namespace rtfact
