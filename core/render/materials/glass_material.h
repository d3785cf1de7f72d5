// GlassMaterial: a smooth dielectric. Schlick's approximation of the Fresnel term
// splits the light between the mirror reflection and the refraction (Snell's law);
// past the critical angle all of it reflects. The hit's `front` mask tells entering
// from leaving, so any scene that reports it (meshes by winding, discs by normal) works.
#pragma once
#include <cmath>

#include "core/concepts/material.h"
#include "core/render/materials/mirror_material.h"

namespace rtfact {

struct GlassMaterial {
    Vec3f albedo{1.0f};
    float ior = 1.5f;

    struct Lobes {
        Vec3f reflect;
        Vec3f refract;         // valid when `refracts`
        float fresnel = 1.0f;  // fraction reflected
        bool refracts = false;
    };

    // Both lobes for unit direction d at shading normal n (facing the ray); `front`: the
    // ray enters the object.
    Lobes lobes(Vec3f d, Vec3f n, bool front) const {
        const float cosi = -dot(d, n);
        const float eta = front ? 1.0f / ior : ior;
        const float k = 1.0f - eta * eta * (1.0f - cosi * cosi);
        Lobes l;
        l.reflect = MirrorMaterial::reflect(d, n);
        if (k > 0.0f) {
            const float r0 = (1.0f - ior) / (1.0f + ior);
            const float cosx = front ? cosi : std::sqrt(k);
            l.fresnel = r0 * r0 + (1.0f - r0 * r0) * std::pow(1.0f - cosx, 5.0f);
            l.refract = normalize(d * eta + n * (eta * cosi - std::sqrt(k)));
            l.refracts = true;
        }
        return l;
    }

    template <int N>
    Vec3<N> eval(const SurfacePoint<N>&, const Vec3<N>&, const Vec3<N>&) const {
        return Vec3<N>(Vec3f(0.0f));
    }

    // u1 picks the lobe with the Fresnel probability, so the weight is the albedo.
    template <int N>
    BsdfSample<N> sample(const SurfacePoint<N>& sp, const Vec3<N>& wo, const Packet<N>& u1, const Packet<N>&) const {
        BsdfSample<N> s;
        s.transmit = Mask<N>(false);
        for (int i = 0; i < N; ++i) {
            const Lobes l = lobes(-wo.lane(i), sp.n.lane(i), sp.front[i]);
            const bool t = l.refracts && !(u1[i] < l.fresnel);
            s.wi.setLane(i, t ? l.refract : l.reflect);
            s.transmit.set(i, t);
        }
        s.weight = Vec3<N>(albedo);
        s.specular = Mask<N>(true);
        s.valid = Mask<N>(true);
        return s;
    }
};
static_assert(Material<GlassMaterial>);

}  // namespace rtfact
