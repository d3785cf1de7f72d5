// RenderCounters: the one statistics mechanism of a frame (rays traced, volume samples
// taken and skipped, LoD nodes that answered rays). Integrators and scenes add to the
// calling thread's copy, with no atomics and no shared cache lines; the tile scheduler
// sums what each tile added into RenderStats.
#pragma once
#include <cstdint>

namespace rtfact {

struct RenderCounters {
    uint64_t rays = 0;
    uint64_t volumeSamples = 0;  // volume samples taken
    uint64_t volumeSkipped = 0;  // volume steps jumped over by empty-space skipping
    uint64_t lodNodesHit = 0;    // shading hits answered by an LoD representative

    RenderCounters& operator+=(const RenderCounters& o) {
        rays += o.rays;
        volumeSamples += o.volumeSamples;
        volumeSkipped += o.volumeSkipped;
        lodNodesHit += o.lodNodesHit;
        return *this;
    }
    friend RenderCounters operator-(const RenderCounters& a, const RenderCounters& b) {
        return {a.rays - b.rays, a.volumeSamples - b.volumeSamples, a.volumeSkipped - b.volumeSkipped,
                a.lodNodesHit - b.lodNodesHit};
    }
};

inline thread_local RenderCounters tlsCounters;

}  // namespace rtfact
