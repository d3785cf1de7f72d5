// SIMD packet operations against plain scalar results, at width 1, the small widths,
// the native width and multi-chunk packets, with partial masks.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/simd/bitmask.h"
#include "core/simd/vec3.h"

using namespace rtfact;

namespace {

template <int N>
Packet<N> randomPacket(std::mt19937& rng, float lo = -100.0f, float hi = 100.0f) {
    std::uniform_real_distribution<float> u(lo, hi);
    Packet<N> p;
    for (int i = 0; i < N; ++i) p[i] = u(rng);
    return p;
}

template <int N>
Mask<N> randomMask(std::mt19937& rng) {
    Mask<N> m;
    for (int i = 0; i < N; ++i) m.set(i, (rng() & 1) != 0);
    return m;
}

template <int N>
void checkOps() {
    std::mt19937 rng(42 + N);
    for (int iter = 0; iter < 50; ++iter) {
        const Packet<N> a = randomPacket<N>(rng), b = randomPacket<N>(rng);
        const Packet<N> pos = randomPacket<N>(rng, 0.01f, 1000.0f);
        const Mask<N> m = randomMask<N>(rng);
        const Packet<N> sum = a + b, dif = a - b, prod = a * b, quo = a / pos;
        const Packet<N> mn = min(a, b), mx = max(a, b), sel = select(m, a, b);
        const Packet<N> sq = sqrt(pos), rc = rcp(pos), fl = floor(a), ab = abs(a);
        const Mask<N> lt = a<b, le = a <= b, gt = a> b, eq = a == a, ne = a != b;
        const Packet<N, int32_t> ai = toInt(a);
        const Packet<N> af = toFloat(ai);
        const int k = int(rng() % 31);
        const Packet<N, int32_t> shl = ai << k, sar = ai >> k;
        for (int i = 0; i < N; ++i) {
            EXPECT_EQ(shl[i], int32_t(uint32_t(ai[i]) << k));
            EXPECT_EQ(sar[i], ai[i] >> k);  // arithmetic: the sign is kept
            const float x = a[i], y = b[i], p = pos[i];
            EXPECT_EQ(sum[i], x + y);
            EXPECT_EQ(dif[i], x - y);
            EXPECT_EQ(prod[i], x * y);
            EXPECT_FLOAT_EQ(quo[i], x / p);
            EXPECT_EQ(mn[i], std::min(x, y));
            EXPECT_EQ(mx[i], std::max(x, y));
            EXPECT_EQ(sel[i], m[i] ? x : y);
            EXPECT_FLOAT_EQ(sq[i], std::sqrt(p));
            EXPECT_NEAR(rc[i], 1.0f / p, 2e-6f * (1.0f / p));  // estimate + Newton step
            EXPECT_EQ(fl[i], std::floor(x));
            EXPECT_EQ(ab[i], std::fabs(x));
            EXPECT_EQ(lt[i], x < y);
            EXPECT_EQ(le[i], x <= y);
            EXPECT_EQ(gt[i], x > y);
            EXPECT_TRUE(eq[i]);
            EXPECT_EQ(ne[i], x != y);
            EXPECT_EQ(ai[i], int32_t(x));
            EXPECT_EQ(af[i], float(int32_t(x)));
        }
        float hmn = a[0], hmx = a[0];
        for (int i = 1; i < N; ++i) {
            hmn = std::min(hmn, a[i]);
            hmx = std::max(hmx, a[i]);
        }
        EXPECT_EQ(hmin(a), hmn);
        EXPECT_EQ(hmax(a), hmx);

        // Mask reductions and bit masks, including partial masks.
        int count = 0;
        for (int i = 0; i < N; ++i) count += m[i];
        EXPECT_EQ(popcount(m), count);
        EXPECT_EQ(any(m), count > 0);
        EXPECT_EQ(all(m), count == N);
        EXPECT_EQ(none(m), count == 0);
        const BitMask<N> bm(m);
        EXPECT_EQ(bm.count(), count);
        int first = N;
        for (int i = N - 1; i >= 0; --i)
            if (m[i]) first = i;
        EXPECT_EQ(bm.first(), first);
        int visited = 0;
        bm.forEach([&](int i) {
            EXPECT_TRUE(m[i]);
            ++visited;
        });
        EXPECT_EQ(visited, count);
        const Mask<N> both = m & lt, either = m | lt, inv = ~m, an = andNot(m, lt);
        for (int i = 0; i < N; ++i) {
            EXPECT_EQ(both[i], m[i] && lt[i]);
            EXPECT_EQ(either[i], m[i] || lt[i]);
            EXPECT_EQ(inv[i], !m[i]);
            EXPECT_EQ(an[i], m[i] && !lt[i]);
        }
    }
    EXPECT_TRUE(all(Mask<N>(true)));
    EXPECT_TRUE(none(Mask<N>(false)));
    EXPECT_TRUE(BitMask<N>(Mask<N>(true)).all());

    // Gathers.
    std::vector<float> table(1000);
    for (int i = 0; i < 1000; ++i) table[size_t(i)] = float(i) * 0.5f;
    Packet<N, int32_t> idx;
    for (int i = 0; i < N; ++i) idx[i] = int32_t(rng() % 1000);
    const Packet<N> g = gather(table.data(), idx);
    for (int i = 0; i < N; ++i) EXPECT_EQ(g[i], float(idx[i]) * 0.5f);

    // Per-chunk iteration sees the same lanes as per-lane access.
    Packet<N> r = Packet<N>::ramp(0.0f);
    for (int k = 0; k < Packet<N>::C; ++k)
        for (int j = 0; j < Packet<N>::W; ++j) EXPECT_EQ(r.chunk(k)[j], float(k * Packet<N>::W + j));

    // Vec3 algebra.
    const Vec3<N> u(randomPacket<N>(rng), randomPacket<N>(rng), randomPacket<N>(rng));
    const Vec3<N> v(randomPacket<N>(rng), randomPacket<N>(rng), randomPacket<N>(rng));
    const Packet<N> d = dot(u, v);
    const Vec3<N> c = cross(u, v), n = normalize(u);
    for (int i = 0; i < N; ++i) {
        const Vec3f su = u.lane(i), sv = v.lane(i);
        EXPECT_NEAR(d[i], rtfact::dot(su, sv), 1e-3f * (1.0f + std::fabs(rtfact::dot(su, sv))));
        const Vec3f sc = rtfact::cross(su, sv);
        EXPECT_NEAR(c.x[i], sc.x, 1e-2f);
        EXPECT_NEAR(c.y[i], sc.y, 1e-2f);
        EXPECT_NEAR(c.z[i], sc.z, 1e-2f);
        EXPECT_NEAR(rtfact::length(n.lane(i)), 1.0f, 1e-5f);
    }
}

}  // namespace

TEST(Simd, NativeWidthMatchesBuild) {
#if defined(RTFACT_FORCE_SCALAR)
    EXPECT_EQ(simd::kNativeWidth, 1);
#else
    EXPECT_GE(simd::kNativeWidth, 4);
#endif
    EXPECT_EQ(Packet<1>::W, 1);
    EXPECT_EQ(Packet<simd::kNativeWidth>::C, 1);
    EXPECT_EQ(Packet<256>::C, 256 / simd::kNativeWidth);
}

TEST(Simd, Width1) { checkOps<1>(); }
TEST(Simd, Width4) { checkOps<4>(); }
TEST(Simd, Native) { checkOps<simd::kNativeWidth>(); }
TEST(Simd, TwoChunks) { checkOps<2 * simd::kNativeWidth>(); }
TEST(Simd, Packet64) { checkOps<64>(); }
TEST(Simd, Packet256) { checkOps<256>(); }
