// Embree helpers shared by the benchmarks that use Embree as the peer.
#pragma once
#include <embree3/rtcore.h>
#include <sys/types.h>

#include <atomic>
#include <string>

#include "core/ray/ray_packet.h"
#include "core/simd/native.h"
#include "core/util/error.h"

namespace rtfact::bench {

// Bytes Embree holds, counted through its memory monitor (rtcSetDeviceMemoryMonitorFunction).
inline std::atomic<int64_t> gEmbreeBytes{0};
inline bool embreeMemory(void*, ssize_t bytes, bool) {
    gEmbreeBytes += bytes;
    return true;
}

// Embree's widest code path at RTfact's build ISA: an avx2 (or sse4) build run on an
// AVX-512 machine stands for an AVX2 (SSE4) CPU, where Embree's runtime dispatch could not
// pick AVX-512 either; the native build leaves Embree free.
inline const char* embreeMaxIsa() {
    if constexpr (simd::kNativeWidth == 16)
        return "avx512";
    else if constexpr (simd::kNativeWidth == 8)
        return "avx2";
    else
        return "sse4.2";
}

// A device with `threads` threads (0: all) and the ISA cap above.
inline RTCDevice newEmbreeDevice(int threads) {
    const std::string cfg = "threads=" + std::to_string(threads) + ",max_isa=" + embreeMaxIsa();
    RTCDevice device = rtcNewDevice(cfg.c_str());
    if (!device) throw Error("", "cannot create an Embree device (" + cfg + ")");
    rtcSetDeviceMemoryMonitorFunction(device, embreeMemory, nullptr);
    return device;
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
