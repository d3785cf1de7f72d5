// Integrator: computes radiance for a packet of camera rays in a scene.
#pragma once
#include "core/ray/ray_packet.h"

namespace rtfact {

// Where a packet's rays come from: pixel coordinates and the sample index (for
// deterministic per-pixel random numbers, independent of threads and packet size).
template <int N>
struct PixelSample {
    Packet<N, int32_t> px, py;
    int sample = 0;
};

template <int N>
struct Radiance {
    Vec3<N> color;
    Packet<N> alpha;
    Packet<N> depth;  // distance along the ray to the first visible thing, inf if none
};

template <class I, class Scene>
concept Integrator = requires(const I& integ, const Scene& scene, RayPacket<1>& r1, RayPacket<simd::kNativeWidth>& rn,
                              const Mask<1>& m1, const Mask<simd::kNativeWidth>& mn, const PixelSample<1>& s1,
                              const PixelSample<simd::kNativeWidth>& sn) {
    { integ.template eval<1>(scene, r1, m1, s1) } -> std::same_as<Radiance<1>>;
    { integ.template eval<simd::kNativeWidth>(scene, rn, mn, sn) } -> std::same_as<Radiance<simd::kNativeWidth>>;
};

}  // namespace rtfact
