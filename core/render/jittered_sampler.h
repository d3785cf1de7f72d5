// Jittered samples: sample 0 is the pixel centre, later ones random positions inside
// the pixel from a per-pixel hash, so progressive rendering converges and stays
// deterministic.
#pragma once
#include "core/concepts/sampler.h"
#include "core/render/random.h"

namespace rtfact {

struct JitteredSampler {
    template <int N>
    RTFACT_INLINE void offsets(const Packet<N, int32_t>& px, const Packet<N, int32_t>& py, int sample, Packet<N>& ox,
                               Packet<N>& oy) const {
        if (sample == 0) {
            ox = Packet<N>(0.5f);
            oy = Packet<N>(0.5f);
            return;
        }
        ox = hashToUnit(px, py, uint32_t(sample), 0u);
        oy = hashToUnit(px, py, uint32_t(sample), 1u);
    }
};
static_assert(Sampler<JitteredSampler>);

}  // namespace rtfact
