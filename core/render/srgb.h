// The sRGB transfer curve (IEC 61966-2-1), in one place: 8-bit image files, the viewer's
// JPEG frames, the Python module's to_srgb8, the tests' image metric and colour maps
// given in sRGB all encode and decode with it.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace rtfact {

// Linear [0, 1] -> sRGB [0, 1]; values outside are clamped, NaN gives 0.
inline float linearToSrgb(float v) {
    v = v > 0.0f ? std::min(v, 1.0f) : 0.0f;
    return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

// sRGB [0, 1] -> linear [0, 1]; values outside are clamped, NaN gives 0.
inline float srgbToLinear(float s) {
    s = s > 0.0f ? std::min(s, 1.0f) : 0.0f;
    return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f);
}

// Linear -> 8-bit sRGB, rounded to nearest.
inline uint8_t linearToSrgb8(float v) { return uint8_t(std::lround(linearToSrgb(v) * 255.0f)); }

}  // namespace rtfact
