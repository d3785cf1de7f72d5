// Directional light (sun): constant radiance from one direction.
#pragma once
#include "core/concepts/light.h"
#include "core/ray/ray_packet.h"  // kInfinity

namespace rtfact {

struct DirectionalLight {
    Vec3f direction{0, -1, 0};  // direction the light travels
    Vec3f radiance{1.0f};

    template <int N>
    RTFACT_INLINE LightSample<N> sample(const Vec3<N>&, const Packet<N>&, const Packet<N>&) const {
        LightSample<N> s;
        s.wi = Vec3<N>(-normalize(direction));
        s.distance = Packet<N>(kInfinity);
        s.radiance = Vec3<N>(radiance);
        return s;
    }
};
static_assert(Light<DirectionalLight>);

}  // namespace rtfact
