// One sample in the centre of each pixel.
#pragma once
#include "core/concepts/sampler.h"

namespace rtfact {

struct PixelCenterSampler {
    template <int N>
    RTFACT_INLINE void offsets(const Packet<N, int32_t>&, const Packet<N, int32_t>&, int, Packet<N>& ox,
                               Packet<N>& oy) const {
        ox = Packet<N>(0.5f);
        oy = Packet<N>(0.5f);
    }
};
static_assert(Sampler<PixelCenterSampler>);

}  // namespace rtfact
