// RayPacket<N>: N rays structure-of-arrays; a single ray is RayPacket<1>.
#pragma once
#include <limits>

#include "core/simd/vec3.h"

namespace rtfact {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

// Conservative bounds of a whole packet for frustum-style culling of coherent packets
// (interval arithmetic on origins and reciprocal directions).
struct PacketBounds {
    Vec3f orgLo, orgHi;
    Vec3f invDirLo, invDirHi;
    float tMinLo = 0, tMaxHi = kInfinity;
    bool uniformSigns = false;  // every ray has the same direction sign on each axis
};

template <int N>
struct RayPacket {
    static constexpr int size = N;
    Vec3<N> org, dir, invDir;
    Packet<N> tMin, tMax;
    bool commonOrigin = false;  // all lanes share org (pinhole camera rays)

    // Reciprocal direction with zero components nudged so the slab test stays finite.
    RTFACT_INLINE void finalize() {
        for (int a = 0; a < 3; ++a) {
            const Packet<N> d = dir[a];
            const Packet<N> tiny(1e-20f);
            const Packet<N> safe = select(abs(d) < tiny, select(d < Packet<N>(0.0f), -tiny, tiny), d);
            invDir[a] = Packet<N>(1.0f) / safe;
        }
    }

    // One lane as a single ray.
    RayPacket<1> lane(int i) const {
        RayPacket<1> r;
        r.org = Vec3<1>(org.lane(i));
        r.dir = Vec3<1>(dir.lane(i));
        r.invDir = Vec3<1>(invDir.lane(i));
        r.tMin = tMin[i];
        r.tMax = tMax[i];
        r.commonOrigin = true;
        return r;
    }
    void setLane(int i, Vec3f o, Vec3f d, float t0 = 0.0f, float t1 = kInfinity) {
        org.setLane(i, o);
        dir.setLane(i, d);
        tMin[i] = t0;
        tMax[i] = t1;
    }

    PacketBounds bounds(const Mask<N>& active) const {
        PacketBounds b;
        b.orgLo = Vec3f(kInfinity);
        b.orgHi = Vec3f(-kInfinity);
        b.invDirLo = Vec3f(kInfinity);
        b.invDirHi = Vec3f(-kInfinity);
        b.tMinLo = kInfinity;
        b.tMaxHi = -kInfinity;
        const Packet<N> inf(kInfinity);
        for (int a = 0; a < 3; ++a) {
            b.orgLo[a] = hmin(select(active, org[a], inf));
            b.orgHi[a] = hmax(select(active, org[a], -inf));
            b.invDirLo[a] = hmin(select(active, invDir[a], inf));
            b.invDirHi[a] = hmax(select(active, invDir[a], -inf));
        }
        b.tMinLo = hmin(select(active, tMin, inf));
        b.tMaxHi = hmax(select(active, tMax, -inf));
        b.uniformSigns = (b.invDirLo.x > 0 || b.invDirHi.x < 0) && (b.invDirLo.y > 0 || b.invDirHi.y < 0) &&
                         (b.invDirLo.z > 0 || b.invDirHi.z < 0);
        return b;
    }
};

// Hit data an intersection query must produce: distance only (shadow rays, depth) or
// everything shading needs (ids, barycentrics/uv, normals).
enum class HitData { Distance, Shading };

}  // namespace rtfact
