// LambertMaterial: ideal diffuse reflection of the surface colour. The scene's colour
// already holds the material's diffuse colour (kd, vertex or point colours).
#pragma once
#include "core/concepts/material.h"
#include "core/render/sampling.h"

namespace rtfact {

struct LambertMaterial {
    // f * cos = colour / pi * cos, zero below the shading normal.
    template <int N>
    Vec3<N> eval(const SurfacePoint<N>& sp, const Vec3<N>&, const Vec3<N>& wi) const {
        const Packet<N> cosT = dot(sp.n, wi);
        return select(cosT > Packet<N>(0.0f), sp.color * (cosT * Packet<N>(1.0f / 3.14159265f)), Vec3<N>(Vec3f(0.0f)));
    }

    // Cosine-weighted directions: the weight f * cos / pdf is the colour itself.
    template <int N>
    BsdfSample<N> sample(const SurfacePoint<N>& sp, const Vec3<N>&, const Packet<N>& u1, const Packet<N>& u2) const {
        BsdfSample<N> s;
        s.wi = cosineHemisphere(sp.n, u1, u2);
        s.weight = sp.color;
        s.specular = Mask<N>(false);
        s.transmit = Mask<N>(false);
        s.valid = Mask<N>(true);
        return s;
    }
};
static_assert(Material<LambertMaterial>);

}  // namespace rtfact
