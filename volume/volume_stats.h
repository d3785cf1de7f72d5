// Frame counters of the volume integrators (samples taken, steps skipped), summed over
// threads with one atomic add per packet.
#pragma once
#include <atomic>
#include <cstdint>

namespace rtfact::volume {

struct VolumeCounters {
    std::atomic<uint64_t> samples{0};
    std::atomic<uint64_t> skipped{0};
    void reset() {
        samples = 0;
        skipped = 0;
    }
};
inline VolumeCounters gVolumeCounters;

}  // namespace rtfact::volume
