// Point light with inverse-square fall-off.
#pragma once
#include "core/concepts/light.h"

namespace rtfact {

struct PointLight {
    Vec3f position;
    Vec3f intensity{1.0f};

    template <int N>
    RTFACT_INLINE LightSample<N> sample(const Vec3<N>& p, const Packet<N>&, const Packet<N>&) const {
        LightSample<N> s;
        const Vec3<N> d = Vec3<N>(position) - p;
        const Packet<N> d2 = dot(d, d);
        const Packet<N> inv = rcp(sqrt(d2));
        s.wi = d * inv;
        s.distance = d2 * inv;
        s.radiance = Vec3<N>(intensity) * rcp(d2);
        return s;
    }
};
static_assert(Light<PointLight>);

}  // namespace rtfact
