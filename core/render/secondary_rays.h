// Which traversal serves an integrator's incoherent rays (AO, diffuse bounces), chosen
// at compile time: the scene's packet structure, or one ray at a time through its wide
// BVH. Scenes without a wide structure (no intersectIncoherent/occludedIncoherent)
// always use their packet queries, so integrators stay generic.
#pragma once
#include <concepts>

#include "core/concepts/scene.h"

namespace rtfact {

struct PacketSecondaryRays {};  // packets through the scene's packet structure
struct WideSecondaryRays {};    // single rays through the scene's wide BVH

template <class T>
concept SecondaryRayPolicy = std::same_as<T, PacketSecondaryRays> || std::same_as<T, WideSecondaryRays>;

// A scene with its own queries for incoherent rays. Named (not an inline probe) so that
// a scene meant to have them can static_assert it: a signature that drifts would
// otherwise send its rays through packets without a word.
template <class Scene, int N>
concept IncoherentQueries = requires(const Scene& scene, const RayPacket<N>& rays, const Mask<N>& active) {
    scene.template intersectIncoherent<N>(rays, active);
    { scene.template occludedIncoherent<N>(rays, active) } -> std::same_as<Mask<N>>;
};

template <SecondaryRayPolicy Policy, int N, class Scene>
auto intersectSecondary(const Scene& scene, const RayPacket<N>& rays, const Mask<N>& active) {
    if constexpr (std::same_as<Policy, WideSecondaryRays> && IncoherentQueries<Scene, N>)
        return scene.template intersectIncoherent<N>(rays, active);
    else
        return scene.template intersect<N>(rays, active);
}

template <SecondaryRayPolicy Policy, int N, class Scene>
Mask<N> occludedSecondary(const Scene& scene, const RayPacket<N>& rays, const Mask<N>& active) {
    if constexpr (std::same_as<Policy, WideSecondaryRays> && IncoherentQueries<Scene, N>)
        return scene.template occludedIncoherent<N>(rays, active);
    else
        return scene.template occluded<N>(rays, active);
}

}  // namespace rtfact
