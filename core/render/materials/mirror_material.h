// MirrorMaterial: a perfect mirror tinted by its albedo (a delta lobe: eval is zero).
#pragma once
#include "core/concepts/material.h"

namespace rtfact {

struct MirrorMaterial {
    Vec3f albedo{1.0f};

    // The mirror direction of unit direction d about the normal n.
    static Vec3f reflect(Vec3f d, Vec3f n) { return d - n * (2.0f * dot(d, n)); }

    template <int N>
    Vec3<N> eval(const SurfacePoint<N>&, const Vec3<N>&, const Vec3<N>&) const {
        return Vec3<N>(Vec3f(0.0f));
    }

    template <int N>
    BsdfSample<N> sample(const SurfacePoint<N>& sp, const Vec3<N>& wo, const Packet<N>&, const Packet<N>&) const {
        BsdfSample<N> s;
        for (int i = 0; i < N; ++i) s.wi.setLane(i, reflect(-wo.lane(i), sp.n.lane(i)));
        s.weight = Vec3<N>(albedo);
        s.specular = Mask<N>(true);
        s.transmit = Mask<N>(false);
        s.valid = Mask<N>(true);
        return s;
    }
};
static_assert(Material<MirrorMaterial>);

}  // namespace rtfact
