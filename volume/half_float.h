// IEEE 754 binary16 ("half") conversions for the transfer-function table: one 64-bit
// entry holds r, g, b, a as four halves, so one 64-bit gather per lane fetches a whole
// entry (the SIMD paths convert with F16C's vcvtph2ps; this is the scalar side, exact
// like it). Relative precision 2^-11 for normal values, absolute 2^-25 below 2^-14.
#pragma once
#include <bit>
#include <cstdint>

namespace rtfact::volume {

// Round to nearest even; overflow gives infinity, NaN stays NaN.
inline uint16_t toHalf(float f) {
    const uint32_t x = std::bit_cast<uint32_t>(f);
    const uint32_t sign = (x >> 16) & 0x8000u;
    const uint32_t absx = x & 0x7fffffffu;
    if (absx >= 0x7f800000u) return uint16_t(sign | 0x7c00u | (absx > 0x7f800000u ? 0x200u : 0u));
    if (absx >= 0x477ff000u) return uint16_t(sign | 0x7c00u);  // rounds past the largest half
    if (absx < 0x38800000u) {
        // subnormal half (or zero): the value in units of 2^-24, rounded to nearest even
        if (absx < 0x33000000u) return uint16_t(sign);  // below half the smallest subnormal
        const uint32_t mant = (absx & 0x7fffffu) | 0x800000u;
        const int shift = 126 - int(absx >> 23);  // 14..24 for exponents -15..-25
        const uint32_t q = mant >> shift, rem = mant & ((1u << shift) - 1u), halfway = 1u << (shift - 1);
        return uint16_t(sign | (q + ((rem > halfway || (rem == halfway && (q & 1u))) ? 1u : 0u)));
    }
    // normal: rebias the exponent, round the 13 dropped mantissa bits (a carry into the
    // exponent is the correct result)
    const uint32_t v = absx - 0x38000000u;
    const uint32_t q = v >> 13, rem = v & 0x1fffu;
    return uint16_t(sign | (q + ((rem > 0x1000u || (rem == 0x1000u && (q & 1u))) ? 1u : 0u)));
}

inline float fromHalf(uint16_t h) {
    const uint32_t sign = uint32_t(h & 0x8000u) << 16, e = (h >> 10) & 0x1fu, m = h & 0x3ffu;
    if (e == 0) {
        // zero or subnormal: m * 2^-24, exact in float
        const float v = float(m) * 0x1p-24f;
        return std::bit_cast<float>(std::bit_cast<uint32_t>(v) | sign);
    }
    if (e == 31) return std::bit_cast<float>(sign | 0x7f800000u | (m << 13));
    return std::bit_cast<float>(sign | ((e + 112u) << 23) | (m << 13));
}

// The table entry: r in bits 0-15, g 16-31, b 32-47, a 48-63.
inline uint64_t packRgbaHalf(float r, float g, float b, float a) {
    return uint64_t(toHalf(r)) | uint64_t(toHalf(g)) << 16 | uint64_t(toHalf(b)) << 32 | uint64_t(toHalf(a)) << 48;
}

}  // namespace rtfact::volume
