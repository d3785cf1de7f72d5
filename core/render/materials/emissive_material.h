// EmissiveMaterial: a surface that emits constant radiance on both sides and scatters
// nothing (an area light). Emission of other materials (OBJ's Ke) adds `emitted` of one.
#pragma once
#include "core/concepts/material.h"

namespace rtfact {

struct EmissiveMaterial {
    Vec3f radiance{0.0f};

    template <int N>
    Vec3<N> emitted(const SurfacePoint<N>&, const Vec3<N>&) const {
        return Vec3<N>(radiance);
    }

    template <int N>
    Vec3<N> eval(const SurfacePoint<N>&, const Vec3<N>&, const Vec3<N>&) const {
        return Vec3<N>(Vec3f(0.0f));
    }

    // Absorbs: no direction continues.
    template <int N>
    BsdfSample<N> sample(const SurfacePoint<N>& sp, const Vec3<N>&, const Packet<N>&, const Packet<N>&) const {
        BsdfSample<N> s;
        s.wi = sp.n;
        s.weight = Vec3<N>(Vec3f(0.0f));
        s.specular = Mask<N>(false);
        s.transmit = Mask<N>(false);
        s.valid = Mask<N>(false);
        return s;
    }
};
static_assert(Material<EmissiveMaterial>);

}  // namespace rtfact
