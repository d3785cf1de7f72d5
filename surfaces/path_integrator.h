// Progressive path tracer for mesh scenes: Lambertian, perfect mirror and dielectric
// glass materials (from MeshMaterial: kd, ks/illum, dissolve/Ni), emission (Ke) as
// area lights, and a constant environment. All lanes of a packet bounce together, so
// secondary rays from different surfaces still travel as one (incoherent) packet; by
// default those bounces are traced one by one through the scene's wide BVH.
// Each --spp sample adds one path per pixel; the framebuffer averages them.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/concepts/integrator.h"
#include "core/concepts/scene.h"
#include "core/render/random.h"
#include "core/render/sampling.h"
#include "core/render/secondary_rays.h"
#include "surfaces/mesh.h"

namespace rtfact {

// The material kinds the path tracer knows, resolved once from MTL-style data.
struct PathMaterial {
    enum Kind : int32_t { Lambert, Mirror, Glass } kind = Lambert;
    Vec3f albedo{0.8f};
    Vec3f emission{0.0f};
    float ior = 1.5f;

    static PathMaterial from(const MeshMaterial& m) {
        PathMaterial p;
        p.emission = m.ke;
        p.ior = m.ior > 1.0f ? m.ior : 1.5f;
        if (m.dissolve < 1.0f || m.illum == 7 || m.illum == 4 || m.illum == 6) {
            p.kind = Glass;
            p.albedo = Vec3f(1.0f);
        } else if (m.illum == 3 || m.illum == 5) {
            p.kind = Mirror;
            p.albedo = maxComponent(m.ks) > 0.0f ? m.ks : Vec3f(1.0f);
        } else {
            p.albedo = m.kd;
        }
        return p;
    }
};

template <SecondaryRayPolicy Secondary = WideSecondaryRays>
struct PathIntegratorT {
    Vec3f background{0.0f};  // constant environment radiance
    int maxDepth = 6;
    int rouletteDepth = 3;                // Russian roulette from this bounce on (unbiased)
    std::vector<PathMaterial> materials;  // by material id; empty: one default Lambert

    template <int N, class Scene>
    Radiance<N> eval(const Scene& scene, RayPacket<N>& camRays, const Mask<N>& active, const PixelSample<N>& ps) const {
        using P = Packet<N>;
        const P zero(0.0f), one(1.0f);
        const AABB box = scene.bounds();
        const float eps = 1e-4f * std::max(length(box.extent()), 1e-6f);
        Radiance<N> out;
        out.alpha = P(1.0f);
        out.depth = P(kInfinity);
        Vec3<N> L(Vec3f(0.0f)), beta(Vec3f(1.0f));
        RayPacket<N> rays = camRays;
        Mask<N> alive = active;
        static const PathMaterial kDefault{};
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
            Mask<N> below(false);  // continue on the far side of the surface
            BitMask<N>(found).forEach([&](int i) {
                const int32_t mid = sp.material[i];
                const PathMaterial& m =
                    materials.empty() || mid < 0 || size_t(mid) >= materials.size() ? kDefault : materials[size_t(mid)];
                emitted.setLane(i, m.emission);
                const Vec3f d = rays.dir.lane(i), n = sp.n.lane(i);
                if (m.kind == PathMaterial::Lambert) {
                    // The scene's colour already holds the material's kd (the default
                    // one for meshes without materials) and vertex colours.
                    weight.setLane(i, sp.color.lane(i));
                    newDir.setLane(i, Vec3f(0.0f));  // sampled below in SIMD
                } else if (m.kind == PathMaterial::Mirror) {
                    weight.setLane(i, m.albedo);
                    newDir.setLane(i, d - n * (2.0f * dot(d, n)));
                } else {
                    // Dielectric: Fresnel (Schlick) picks reflection or refraction.
                    // n faces the incoming ray; the winding of the stored triangle tells
                    // inside from outside (closed, outward-oriented meshes).
                    const uint32_t t = uint32_t(hit.id[i]);
                    const Mesh& mesh = *scene.mesh;
                    const Vec3f a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                                c = mesh.positions[mesh.indices[3 * t + 2]];
                    const bool inside = dot(cross(b - a, c - a), d) > 0.0f;  // leaving the object
                    const float eta = inside ? m.ior : 1.0f / m.ior;
                    const float cosi = -dot(d, n);
                    const float k = 1.0f - eta * eta * (1.0f - cosi * cosi);
                    float fr = 1.0f;
                    if (k > 0.0f) {
                        const float r0 = (1.0f - m.ior) / (1.0f + m.ior);
                        const float cosx = inside ? std::sqrt(k) : cosi;
                        fr = r0 * r0 + (1.0f - r0 * r0) * std::pow(1.0f - cosx, 5.0f);
                    }
                    weight.setLane(i, m.albedo);
                    if (u3[i] < fr) {
                        newDir.setLane(i, d + n * (2.0f * cosi));
                    } else {
                        newDir.setLane(i, normalize(d * eta + n * (eta * cosi - std::sqrt(k))));
                        below.set(i, true);
                    }
                }
            });
            L = select(found, L + beta * emitted, L);
            // Lambert lanes: cosine-weighted directions (weight = albedo).
            const Mask<N> diffuse = found & (dot(newDir, newDir) == zero);
            if (any(diffuse)) newDir = select(diffuse, cosineHemisphere(sp.n, u1, u2), newDir);
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

    static std::vector<PathMaterial> fromMesh(const Mesh& m) {
        std::vector<PathMaterial> r;
        for (const MeshMaterial& mm : m.materials) r.push_back(PathMaterial::from(mm));
        return r;
    }
};

using PathIntegrator = PathIntegratorT<>;

}  // namespace rtfact
