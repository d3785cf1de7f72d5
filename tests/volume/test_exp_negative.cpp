// expNegative (the pre-integrated march's e^-x) against std::exp in double precision, at
// width 1, the native width and a packet of several native chunks, over [0, 87]: relative
// error within 2^-21 + x 2^-23 (a few float ulps, plus the rounding of x log2(e) to float,
// whose ulp grows with x), the opacity 1 - e^-x within 2^-23 absolute; exactly 1 at 0 (a
// segment without extinction adds no opacity), and an opacity of 1 in float from 87 up,
// infinity included.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "volume/exp_negative.h"

using namespace rtfact;
using namespace rtfact::volume;

namespace {

// e^-x of every value, W lanes at a time (the tail padded with zeros).
template <int W>
std::vector<float> expNegativeOf(const std::vector<float>& xs) {
    std::vector<float> out(xs.size());
    for (size_t i = 0; i < xs.size(); i += W) {
        Packet<W> x(0.0f);
        for (int k = 0; k < W && i + size_t(k) < xs.size(); ++k) x[k] = xs[i + size_t(k)];
        const Packet<W> e = expNegative<W>(x);
        for (int k = 0; k < W && i + size_t(k) < xs.size(); ++k) out[i + size_t(k)] = e[k];
    }
    return out;
}

// A dense sweep of [0, 87] plus random values, spread evenly in x and in log x.
std::vector<float> sweep() {
    std::vector<float> xs;
    for (int i = 0; i <= 87 * 4096; ++i) xs.push_back(float(i) / 4096.0f);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> lin(0.0f, 87.0f), lg(-30.0f, std::log(87.0f));
    for (int i = 0; i < 100000; ++i) {
        xs.push_back(lin(rng));
        xs.push_back(std::min(87.0f, std::exp(lg(rng))));
    }
    return xs;
}

template <int W>
void expectCloseToStdExp() {
    const std::vector<float> xs = sweep();
    const std::vector<float> e = expNegativeOf<W>(xs);
    double worst = 0.0, worstOpacity = 0.0;  // relative error over its bound; opacity error
    size_t worstAt = 0, worstOpacityAt = 0;
    for (size_t i = 0; i < xs.size(); ++i) {
        const double ref = std::exp(-double(xs[i]));
        const double rel = std::fabs(double(e[i]) - ref) / ref / (0x1p-21 + double(xs[i]) * 0x1p-23);
        if (rel > worst) worst = rel, worstAt = i;
        const double da = std::fabs(double(1.0f - e[i]) - (1.0 - ref));
        if (da > worstOpacity) worstOpacity = da, worstOpacityAt = i;
    }
    EXPECT_LE(worst, 1.0) << "width " << W << ": x = " << xs[worstAt] << " gives " << e[worstAt] << ", exp "
                          << std::exp(-double(xs[worstAt]));
    EXPECT_LE(worstOpacity, 0x1p-23) << "width " << W << ": x = " << xs[worstOpacityAt] << " gives the opacity "
                                     << 1.0f - e[worstOpacityAt] << " (error " << worstOpacity << ")";
}

template <int W>
void expectEnds() {
    const float inf = std::numeric_limits<float>::infinity();
    const std::vector<float> xs = {0.0f, 87.0f, 87.5f, 88.0f, 104.0f, 1e6f, 3.4e38f, inf};
    const std::vector<float> e = expNegativeOf<W>(xs);
    EXPECT_EQ(e[0], 1.0f) << "width " << W;
    for (size_t i = 1; i < xs.size(); ++i) {
        EXPECT_GT(e[i], 0.0f) << "width " << W << ", x = " << xs[i];
        EXPECT_LE(e[i], 1.7e-38f) << "width " << W << ", x = " << xs[i];
        EXPECT_EQ(1.0f - e[i], 1.0f) << "width " << W << ", x = " << xs[i];
    }
}

}  // namespace

TEST(ExpNegative, MatchesStdExpToFloatPrecision) {
    expectCloseToStdExp<1>();
    expectCloseToStdExp<simd::kNativeWidth>();
    expectCloseToStdExp<4 * simd::kNativeWidth>();
}

TEST(ExpNegative, ZeroGivesOneAndLargeValuesAnOpacityOfOne) {
    expectEnds<1>();
    expectEnds<simd::kNativeWidth>();
    expectEnds<4 * simd::kNativeWidth>();
}
