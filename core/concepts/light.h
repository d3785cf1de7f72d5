// Light: samples a direction towards the light from shading points.
#pragma once
#include "core/simd/vec3.h"

namespace rtfact {

template <int N>
struct LightSample {
    Vec3<N> wi;          // unit direction towards the light
    Packet<N> distance;  // to the sampled light point (inf for directional lights)
    Vec3<N> radiance;    // incident radiance / pdf
};

template <class L>
concept Light = requires(const L& l, const Vec3<1>& p1, const Vec3<simd::kNativeWidth>& pn, const Packet<1>& u1,
                         const Packet<simd::kNativeWidth>& un) {
    { l.template sample<1>(p1, u1, u1) } -> std::same_as<LightSample<1>>;
    { l.template sample<simd::kNativeWidth>(pn, un, un) } -> std::same_as<LightSample<simd::kNativeWidth>>;
};

}  // namespace rtfact
