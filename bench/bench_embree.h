// Embree helpers shared by the benchmarks that use Embree as the peer.
#pragma once
#include <embree3/rtcore.h>
#include <sys/types.h>

#include <atomic>

#include "core/ray/ray_packet.h"

namespace rtfact::bench {

// Bytes Embree holds, counted through its memory monitor (rtcSetDeviceMemoryMonitorFunction).
inline std::atomic<int64_t> gEmbreeBytes{0};
inline bool embreeMemory(void*, ssize_t bytes, bool) {
    gEmbreeBytes += bytes;
    return true;
}

// Fills an Embree 16-ray hit structure from our packet (tnear 0, tfar infinite).
inline void toEmbree(const RayPacket<16>& rays, RTCRayHit16& rh) {
    for (int i = 0; i < 16; ++i) {
        rh.ray.org_x[i] = rays.org.x[i];
        rh.ray.org_y[i] = rays.org.y[i];
        rh.ray.org_z[i] = rays.org.z[i];
        rh.ray.dir_x[i] = rays.dir.x[i];
        rh.ray.dir_y[i] = rays.dir.y[i];
        rh.ray.dir_z[i] = rays.dir.z[i];
        rh.ray.tnear[i] = 0.0f;
        rh.ray.tfar[i] = kInfinity;
        rh.ray.time[i] = 0.0f;
        rh.ray.mask[i] = ~0u;
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
    }
}

}  // namespace rtfact::bench
