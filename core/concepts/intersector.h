// Intersectors nest like the structures they traverse: an ElementIntersector tests one
// element against a packet; an Intersector traverses a structure and calls a nested one.
#pragma once
#include <concepts>
#include <cstdint>

#include "core/concepts/primitive.h"
#include "core/ray/ray_packet.h"

namespace rtfact {

// Hit records are defined by element intersectors; they all carry the distance and the
// id of the element hit (-1 for none).
template <class H>
concept HitRecord = requires(H h) {
    h.t;
    h.id;
};

// An element intersector tests chunks [firstChunk, C) of the packet against one element
// and updates hit.t / hit.id (and shading fields) of lanes with tMin < t < hit.t. The
// traversal deactivates lanes by setting hit.t to -inf, so no mask is passed.
template <class I, class E, int N>
concept ElementIntersectorAt = requires(const I& isect, const E& e, uint32_t id, const RayPacket<N>& rays,
                                        typename I::template Hit<N>& hit) {
    requires HitRecord<typename I::template Hit<N>>;
    isect.template intersect<HitData::Distance>(e, id, rays, hit, 0);
    isect.template intersect<HitData::Shading>(e, id, rays, hit, 0);
};

template <class I, class E>
concept ElementIntersector =
    Primitive<E> && ElementIntersectorAt<I, E, 1> && ElementIntersectorAt<I, E, simd::kNativeWidth>;

template <class I, class A, int N>
concept IntersectorAt = requires(const I& isect, const A& accel, const RayPacket<N>& rays,
                                 typename I::template Hit<N>& hit, const Mask<N>& active) {
    isect.template intersect<false, HitData::Shading>(accel, rays, hit, active);
    isect.template intersect<true, HitData::Distance>(accel, rays, hit, active);
    { isect.template occluded<false>(accel, rays, active) } -> std::same_as<Mask<N>>;
};

// An Intersector answers nearest-hit and any-hit queries on a structure A.
template <class I, class A>
concept Intersector = IntersectorAt<I, A, 1> && IntersectorAt<I, A, simd::kNativeWidth>;

}  // namespace rtfact
