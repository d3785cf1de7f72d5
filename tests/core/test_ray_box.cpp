// Ray/box slab tests (per chunk, common and distinct origins) against a double-precision
// reference, and the packet frustum test: it may only say "miss" when every ray misses.
#include <gtest/gtest.h>

#include <random>

#include "core/accel/ray_box.h"

using namespace rtfact;

namespace {

bool referenceHit(const Vec3f& lo, const Vec3f& hi, Vec3f o, Vec3f d, double t0, double t1) {
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0f) {
            if (o[a] < lo[a] || o[a] > hi[a]) return false;
            continue;
        }
        double ta = (double(lo[a]) - o[a]) / d[a], tb = (double(hi[a]) - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1;
}

template <int N, bool CO>
void check() {
    std::mt19937 rng(77 + N + CO);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int hits = 0, misses = 0, culled = 0;
    for (int iter = 0; iter < 400; ++iter) {
        const Vec3f c{u(rng) * 3, u(rng) * 3, u(rng) * 3},
            e{std::fabs(u(rng)) + 0.05f, std::fabs(u(rng)) + 0.05f, std::fabs(u(rng)) + 0.05f};
        const Vec3f lo = c - e, hi = c + e;
        RayPacket<N> r;
        const Vec3f o0{u(rng) * 8, u(rng) * 8, 10.0f};
        const Vec3f aim = iter % 2 ? c : Vec3f{u(rng) * 8, u(rng) * 8, 0.0f};
        for (int i = 0; i < N; ++i) {
            const Vec3f o = CO ? o0 : o0 + Vec3f(u(rng), u(rng), u(rng)) * 0.5f;
            Vec3f d = normalize(aim + Vec3f(u(rng), u(rng), u(rng)) * 1.5f - o);
            if (i % 13 == 5) d.x = 0.0f;  // axis-parallel rays
            r.setLane(i, o, d, 0.0f, i % 5 == 0 ? 4.0f + 8.0f * std::fabs(u(rng)) : kInfinity);
        }
        r.commonOrigin = CO;
        r.finalize();
        bool anyRef = false;
        for (int k = 0; k < Packet<N>::C; ++k) {
            const auto m = chunkHitsBox<CO>(lo, hi, r, r.tMax, k);
            for (int j = 0; j < Packet<N>::W; ++j) {
                const int i = k * Packet<N>::W + j;
                const bool ref = referenceHit(lo, hi, r.org.lane(i), r.dir.lane(i), r.tMin[i], r.tMax[i]);
                anyRef |= ref;
                EXPECT_EQ(bool(m[j]), ref) << "lane " << i << " iter " << iter;
                (ref ? hits : misses)++;
            }
        }
        const PacketBounds pb = r.bounds(Mask<N>(true));
        if (pb.uniformSigns && packetMissesBox(lo, hi, pb, pb.tMaxHi)) {
            EXPECT_FALSE(anyRef) << "frustum test culled a box that a ray hits, iter " << iter;
            ++culled;
        }
    }
    EXPECT_GT(hits, 0);
    EXPECT_GT(misses, 0);
    if constexpr (N >= 16) {
        EXPECT_GT(culled, 0);  // the frustum test must cull something
    }
}

}  // namespace

TEST(RayBox, SingleRay) {
    check<1, true>();
    check<1, false>();
}
TEST(RayBox, NativeChunk) {
    check<simd::kNativeWidth, true>();
    check<simd::kNativeWidth, false>();
}
TEST(RayBox, Packet64) {
    check<64, true>();
    check<64, false>();
}
