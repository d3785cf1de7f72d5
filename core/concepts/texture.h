// Texture: a colour looked up per lane from surface coordinates.
#pragma once
#include "core/simd/vec3.h"

namespace rtfact {

template <class T>
concept Texture = requires(const T& t, const Packet<1>& u1, const Packet<simd::kNativeWidth>& un, const Vec3<1>& p1,
                           const Vec3<simd::kNativeWidth>& pn) {
    { t.template lookup<1>(u1, u1, p1) } -> std::same_as<Vec3<1>>;
    { t.template lookup<simd::kNativeWidth>(un, un, pn) } -> std::same_as<Vec3<simd::kNativeWidth>>;
};

}  // namespace rtfact
