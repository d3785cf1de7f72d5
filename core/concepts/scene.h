// GeometryScene: what surface integrators need from a scene of any kind (spheres,
// meshes, point clouds): nearest hits, occlusion, and shading data at hits.
#pragma once
#include <concepts>

#include "core/concepts/material.h"
#include "core/math/aabb.h"
#include "core/ray/ray_packet.h"

namespace rtfact {

template <class S, int N>
concept GeometrySceneAt = requires(const S& s, const RayPacket<N>& rays, const Mask<N>& m,
                                   const typename S::template Hit<N>& hit) {
    { s.template intersect<N>(rays, m) } -> std::same_as<typename S::template Hit<N>>;
    { s.template occluded<N>(rays, m) } -> std::same_as<Mask<N>>;
    { s.template surface<N>(rays, hit, m) } -> std::same_as<SurfacePoint<N>>;
};

template <class S>
concept GeometryScene = GeometrySceneAt<S, 1> && GeometrySceneAt<S, simd::kNativeWidth> && requires(const S& s) {
    { s.bounds() } -> std::convertible_to<AABB>;
};

}  // namespace rtfact
