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

// The least a GeometryScene offers (declarations only, never called). Integrators
// written against the concept assert with it that they model Integrator for every
// scene kind, next to their definition.
struct GeometrySceneArchetype {
    template <int N>
    struct Hit {
        Packet<N> t;
        Packet<N, int32_t> id;
    };
    template <int N>
    Hit<N> intersect(const RayPacket<N>&, const Mask<N>&) const;
    template <int N>
    Mask<N> occluded(const RayPacket<N>&, const Mask<N>&) const;
    template <int N>
    SurfacePoint<N> surface(const RayPacket<N>&, const Hit<N>&, const Mask<N>&) const;
    AABB bounds() const;
};
static_assert(GeometryScene<GeometrySceneArchetype>);

}  // namespace rtfact
