// The transfer-function table as four halves per entry (half_float.h): the conversions
// round to nearest and are exact back, the packet gather decodes what the scalar path
// decodes bit for bit, and every entry of a scene's tables (1, 2 and 4 steps) is the float
// table's value within half precision (2^-11 relative, 2^-25 absolute below 2^-14).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "volume/half_float.h"
#include "volume/volume_generators.h"
#include "volume/volume_integrator.h"
#include "volume/volume_scene.h"

using namespace rtfact;
using namespace rtfact::volume;

namespace {

constexpr int kW = simd::kNativeWidth;

// |f - half(f)| bound: half an ulp of a half.
float halfTolerance(float f) { return std::max(std::fabs(f) * 0x1p-11f, 0x1p-25f); }

}  // namespace

TEST(HalfFloat, EveryHalfConvertsExactlyBack) {
    for (uint32_t h = 0; h < 0x10000u; ++h) {
        const float f = fromHalf(uint16_t(h));
        if (std::isnan(f)) {
            EXPECT_TRUE(std::isnan(fromHalf(toHalf(f)))) << h;
            continue;
        }
        EXPECT_EQ(toHalf(f), uint16_t(h)) << h;
    }
    EXPECT_EQ(fromHalf(0x3c00), 1.0f);
    EXPECT_EQ(fromHalf(0x0001), 0x1p-24f);       // smallest subnormal
    EXPECT_EQ(fromHalf(0x7bff), 65504.0f);       // largest finite
    EXPECT_EQ(toHalf(65520.0f), 0x7c00);         // rounds past it: infinity
    EXPECT_EQ(toHalf(0x1p-25f), 0x0000);         // tie between 0 and 2^-24: even
    EXPECT_EQ(toHalf(0x1.8p-24f), 0x0002);       // tie between 1 and 2 subnormal units: even
    EXPECT_EQ(toHalf(1.0f + 0x1p-11f), 0x3c00);  // tie: even
    EXPECT_EQ(toHalf(1.0f + 0x1.8p-10f), 0x3c02);
}

TEST(HalfFloat, RoundsToNearest) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> expo(-30.0f, 15.0f), mant(1.0f, 2.0f);
    for (int it = 0; it < 200000; ++it) {
        const float f = std::ldexp(mant(rng), int(std::floor(expo(rng))));
        const uint16_t h = toHalf(f);
        const float back = fromHalf(h);
        EXPECT_LE(std::fabs(back - f), halfTolerance(f)) << f;
        // no neighbour is closer
        if (h > 0) {
            EXPECT_LE(std::fabs(back - f), std::fabs(fromHalf(uint16_t(h - 1)) - f)) << f;
        }
        if (h < 0x7bff) {
            EXPECT_LE(std::fabs(back - f), std::fabs(fromHalf(uint16_t(h + 1)) - f)) << f;
        }
        EXPECT_EQ(toHalf(-f), uint16_t(h | 0x8000u)) << f;
    }
}

// The packet gather (F16C on AVX2 and AVX-512) against the scalar decode, bit for bit.
TEST(HalfFloat, PacketGatherMatchesScalarDecode) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<uint64_t> table(1000);
    for (uint64_t& e : table) e = packRgbaHalf(u(rng), u(rng), u(rng), u(rng) * u(rng) * 0.01f);
    std::uniform_int_distribution<int32_t> pick(0, int32_t(table.size()) - 1);
    for (int it = 0; it < 500; ++it) {
        Packet<kW, int32_t> idx;
        for (int i = 0; i < kW; ++i) idx[i] = pick(rng);
        Packet<kW> r, g, b, a;
        fetchRgbaHalf<kW>(table.data(), idx, r, g, b, a);
        for (int i = 0; i < kW; ++i) {
            const uint64_t e = table[size_t(idx[i])];
            EXPECT_EQ(r[i], fromHalf(uint16_t(e)));
            EXPECT_EQ(g[i], fromHalf(uint16_t(e >> 16)));
            EXPECT_EQ(b[i], fromHalf(uint16_t(e >> 32)));
            EXPECT_EQ(a[i], fromHalf(uint16_t(e >> 48)));
        }
    }
}

// The scene's half tables against the float TF table they are made from.
TEST(HalfFloat, SceneTablesMatchTheFloatTableWithinHalfPrecision) {
    TransferFunction tf;
    tf.colors = {{0.0f, {0.1f, 0.2f, 0.9f}}, {0.5f, {1.0f, 0.5f, 0.0f}}, {1.0f, {1, 1, 1}}};
    tf.opacity = {{0.0f, 0.0f}, {0.3f, 0.0f}, {0.6f, 0.004f}, {1.0f, 0.8f}};
    const TFTable table = buildTable(tf, {0.0f, 255.0f}, 0.5f);
    const BrickedVolume bv = brickVolume(makeSlab(9, 9, 17, 2, 14, 200));
    const VolumeScene<uint8_t> s(bv, table, {});
    const size_t n = size_t(table.size);
    ASSERT_EQ(s.rgbaSteps.size(), 3 * n);
    for (int m = 0; m < 3; ++m)
        for (size_t e = 0; e < n; ++e) {
            const uint64_t v = s.rgbaSteps[size_t(m) * n + e];
            const float a = 1.0f - std::pow(1.0f - table.a[e], float(1 << m));
            EXPECT_NEAR(fromHalf(uint16_t(v)), table.r[e], halfTolerance(table.r[e])) << m << " " << e;
            EXPECT_NEAR(fromHalf(uint16_t(v >> 16)), table.g[e], halfTolerance(table.g[e])) << m << " " << e;
            EXPECT_NEAR(fromHalf(uint16_t(v >> 32)), table.b[e], halfTolerance(table.b[e])) << m << " " << e;
            EXPECT_NEAR(fromHalf(uint16_t(v >> 48)), a, halfTolerance(a)) << m << " " << e;
            // invisible stays invisible (empty-space skipping relies on it)
            EXPECT_EQ(fromHalf(uint16_t(v >> 48)) > 0.0f, table.a[e] > 0.0f) << m << " " << e;
        }
}
