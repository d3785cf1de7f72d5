// expNegative: e^-x per lane for x >= 0, for the pre-integrated march's segment opacity
// 1 - e^-(extinction x length). 2^y with y = -x log2(e) split into round(y) (added to the
// float's exponent) and a remainder in [-1/2, 1/2], whose 2^f is the Taylor series of
// e^(f ln 2) to degree 7 (truncation error < 5.2e-9 relative; degree 6 left 1.2e-7, two
// ulps, which the test of 2^-23 on the opacity caught). y rounded to float adds
// up to x 2^-24 relative (4e-6 at x = 87, where e^-x is 1.6e-38): the opacity 1 - e^-x
// stays within float precision (tests/volume/test_exp_negative.cpp). x is
// clamped at 87 (infinity included), whose e^-87 = 1.6e-38 is still a normal float: an
// opacity of 1.
#pragma once
#include <cstring>

#include "core/simd/vec3.h"

namespace rtfact::volume {

namespace exp_negative_detail {
inline constexpr double kLn2 = 0.69314718055994530942;
// (ln 2)^k / k!
inline constexpr float taylor(int k) {
    double c = 1.0;
    for (int i = 1; i <= k; ++i) c = c * kLn2 / i;
    return float(c);
}
}  // namespace exp_negative_detail

template <int W>
RTFACT_INLINE Packet<W> expNegative(const Packet<W>& x) {
    using P = Packet<W>;
    using I = Packet<W, int32_t>;
    using exp_negative_detail::taylor;
    const P y = min(x, P(87.0f)) * P(-1.44269504088896341f);  // >= -125.6: a normal result
    const P n = floor(y + P(0.5f));
    const P f = y - n;
    P p(taylor(7));
    p = fma(p, f, P(taylor(6)));
    p = fma(p, f, P(taylor(5)));
    p = fma(p, f, P(taylor(4)));
    p = fma(p, f, P(taylor(3)));
    p = fma(p, f, P(taylor(2)));
    p = fma(p, f, P(taylor(1)));
    p = fma(p, f, P(1.0f));
    static_assert(sizeof(P) == sizeof(I));
    I bits;
    std::memcpy(&bits, &p, sizeof bits);
    bits = bits + (toInt(n) << 23);
    std::memcpy(&p, &bits, sizeof p);
    return p;
}

}  // namespace rtfact::volume
