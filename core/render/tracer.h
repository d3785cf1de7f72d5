// Tracer<Isect>: answers nearest-hit and occlusion queries on a structure for packets
// of any size. It picks the common-origin specialisation at run time and counts rays,
// so domain scenes don't each repeat that plumbing.
#pragma once
#include "core/concepts/intersector.h"
#include "core/render/render_counters.h"

namespace rtfact {

template <class Isect>
struct Tracer {
    Isect isect{};
    template <int N>
    using Hit = typename Isect::template Hit<N>;

    template <HitData D = HitData::Shading, class Accel, int N>
    Hit<N> intersect(const Accel& accel, const RayPacket<N>& rays, const Mask<N>& active) const {
        tlsCounters.rays += uint64_t(popcount(active));
        Hit<N> hit;
        if (rays.commonOrigin)
            isect.template intersect<true, D>(accel, rays, hit, active);
        else
            isect.template intersect<false, D>(accel, rays, hit, active);
        return hit;
    }
    template <class Accel, int N>
    Mask<N> occluded(const Accel& accel, const RayPacket<N>& rays, const Mask<N>& active) const {
        tlsCounters.rays += uint64_t(popcount(active));
        if (rays.commonOrigin) return isect.template occluded<true>(accel, rays, active);
        return isect.template occluded<false>(accel, rays, active);
    }
};

}  // namespace rtfact
