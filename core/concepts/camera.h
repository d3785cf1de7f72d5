// Camera: maps continuous pixel coordinates to rays.
#pragma once
#include "core/ray/ray_packet.h"

namespace rtfact {

// Ray footprint as a cone: width(t) = base + slope * t, in world units.
struct RayCone {
    float base = 0.0f;
    float slope = 0.0f;
};

template <class C>
concept Camera = requires(const C& cam, const Packet<1>& x1, const Packet<simd::kNativeWidth>& xn, RayPacket<1>& r1,
                          RayPacket<simd::kNativeWidth>& rn) {
    cam.template generate<1>(x1, x1, r1);
    cam.template generate<simd::kNativeWidth>(xn, xn, rn);
    { cam.cone() } -> std::convertible_to<RayCone>;
    { cam.width() } -> std::convertible_to<int>;
    { cam.height() } -> std::convertible_to<int>;
};

}  // namespace rtfact
