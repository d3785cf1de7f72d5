#include "points/point_colors.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace rtfact::points {

namespace {

float toLinear(float s) { return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f); }
Vec3f linear(int r, int g, int b) { return Vec3f(toLinear(r / 255.0f), toLinear(g / 255.0f), toLinear(b / 255.0f)); }

// Colormaps as sRGB samples at 9 evenly spaced points, interpolated linearly in sRGB:
// viridis and inferno from their published definitions (van der Walt and Smith, 2015);
// "turbo" is a rainbow in the manner of Google's Turbo (dark blue - cyan - green -
// yellow - red) for the most distinct levels; grayscale is black to white.
struct Map {
    const char* name;
    unsigned char rgb[9][3];
};
constexpr Map kMaps[] = {
    {"viridis",
     {{68, 1, 84},
      {71, 45, 123},
      {59, 82, 139},
      {44, 114, 142},
      {33, 145, 140},
      {40, 174, 128},
      {94, 201, 98},
      {173, 220, 48},
      {253, 231, 37}}},
    {"inferno",
     {{0, 0, 4},
      {27, 12, 65},
      {74, 12, 107},
      {120, 28, 109},
      {165, 44, 96},
      {207, 68, 70},
      {237, 105, 37},
      {251, 155, 6},
      {252, 255, 164}}},
    {"turbo",
     {{48, 18, 59},
      {70, 107, 227},
      {40, 188, 235},
      {50, 241, 152},
      {164, 252, 60},
      {237, 208, 58},
      {251, 128, 34},
      {210, 49, 5},
      {122, 4, 3}}},
    {"grayscale",
     {{0, 0, 0},
      {32, 32, 32},
      {64, 64, 64},
      {96, 96, 96},
      {128, 128, 128},
      {159, 159, 159},
      {191, 191, 191},
      {223, 223, 223},
      {255, 255, 255}}},
};

const Map& mapNamed(const std::string& name) {
    for (const Map& m : kMaps)
        if (name == m.name) return m;
    std::string all;
    for (const Map& m : kMaps) all += std::string(all.empty() ? "" : ", ") + m.name;
    throw Error("--colormap", "unknown colormap '" + name + "' (one of " + all + ")");
}

Vec3f sample(const Map& m, float t) {
    t = std::isfinite(t) ? std::clamp(t, 0.0f, 1.0f) * 8.0f : 0.0f;
    const int i = std::min(7, int(t));
    const float f = t - float(i);
    Vec3f c;
    for (int k = 0; k < 3; ++k) c[k] = toLinear(((1 - f) * m.rgb[i][k] + f * m.rgb[i + 1][k]) / 255.0f);
    return c;
}

// Colours a writer filled with zeros are no colours.
bool realColors(const PointCloud& c) {
    if (c.colors.size() != c.size()) return false;
    return std::any_of(c.colors.begin(), c.colors.end(), [](const auto& k) { return k[0] | k[1] | k[2]; });
}

}  // namespace

const std::vector<std::string>& colorModeNames() {
    static const std::vector<std::string> n{"auto",           "rgb",    "elevation", "intensity",
                                            "classification", "return", "lod",       "normal"};
    return n;
}

const std::vector<std::string>& colormapNames() {
    static const std::vector<std::string> n = [] {
        std::vector<std::string> v;
        for (const Map& m : kMaps) v.push_back(m.name);
        return v;
    }();
    return n;
}

namespace {
const std::pair<const char*, ColorMode> kModeNames[] = {
    {"auto", ColorMode::Auto},
    {"rgb", ColorMode::Rgb},
    {"elevation", ColorMode::Elevation},
    {"intensity", ColorMode::Intensity},
    {"classification", ColorMode::Classification},
    {"return", ColorMode::Return},
    {"lod", ColorMode::Lod},
    {"normal", ColorMode::Normal},
};
}  // namespace

std::string colorModeName(ColorMode mode) {
    for (const auto& [n, m] : kModeNames)
        if (m == mode) return n;
    return "attr";
}

ColorOptions parseColorOptions(const std::string& s) {
    ColorOptions o;
    for (const auto& [n, m] : kModeNames)
        if (s == n) {
            o.mode = m;
            return o;
        }
    if (s.rfind("attr:", 0) == 0 && s.size() > 5) {
        o.mode = ColorMode::Attribute;
        o.attribute = s.substr(5);
        return o;
    }
    throw Error("--color", "'" + s +
                               "' is not one of rgb, elevation, intensity, classification, return, attr:NAME, "
                               "lod, normal, auto");
}

Vec3f colormap(const std::string& name, float t) { return sample(mapNamed(name), t); }

Vec3f classificationColor(int cls) {
    // Classes 0-18 of the LAS 1.4 specification (ASPRS): never classified, unclassified,
    // ground, low/medium/high vegetation, building, low noise, reserved, water, rail,
    // road surface, reserved, wire guard, wire conductor, transmission tower, wire
    // connector, bridge deck, high noise.
    static const unsigned char table[19][3] = {{150, 150, 150}, {200, 200, 200}, {160, 110, 60}, {150, 210, 90},
                                               {70, 170, 60},   {20, 110, 30},   {220, 80, 50},  {255, 0, 255},
                                               {255, 255, 0},   {30, 110, 230},  {120, 80, 120}, {90, 90, 90},
                                               {230, 230, 130}, {230, 200, 30},  {240, 150, 30}, {150, 50, 150},
                                               {230, 130, 200}, {130, 130, 180}, {255, 0, 150}};
    if (cls >= 0 && cls < 19) return linear(table[cls][0], table[cls][1], table[cls][2]);
    // User-defined classes: a fixed colour per code, spread around the hue circle.
    return sample(kMaps[2], std::fmod(float(cls) * 0.618034f, 1.0f));
}

std::array<float, 2> robustRange(std::span<const float> v) {
    std::vector<float> s;
    const size_t stride = std::max<size_t>(1, v.size() / 1000000);
    for (size_t i = 0; i < v.size(); i += stride)
        if (std::isfinite(v[i])) s.push_back(v[i]);
    if (s.empty()) return {0, 1};
    auto pct = [&](double p) {
        const size_t k = std::min(s.size() - 1, size_t(p * double(s.size() - 1) + 0.5));
        std::nth_element(s.begin(), s.begin() + ptrdiff_t(k), s.end());
        return s[k];
    };
    float lo = pct(0.02), hi = pct(0.98);
    if (!(hi > lo)) {
        lo = *std::min_element(s.begin(), s.end());
        hi = *std::max_element(s.begin(), s.end());
    }
    if (!(hi > lo)) hi = lo + 1;
    return {lo, hi};
}

ColorMode resolveColorMode(const PointCloud& c, ColorMode mode) {
    if (mode != ColorMode::Auto) return mode;
    return realColors(c) ? ColorMode::Rgb : ColorMode::Elevation;
}

std::vector<Vec3f> pointColors(const PointCloud& c, const ColorOptions& opt, const std::string& source) {
    const size_t n = c.size();
    const ColorMode mode = resolveColorMode(c, opt.mode);
    std::vector<Vec3f> out(n, Vec3f(0.85f, 0.85f, 0.85f));
    auto each = [&](auto f) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) out[i] = f(i);
        });
    };
    // A scalar through the colormap over the given or robust range.
    auto mapped = [&](std::span<const float> v, double offset, const char* defaultMap) {
        const Map& m = mapNamed(opt.colormap.empty() ? defaultMap : opt.colormap);
        std::array<float, 2> r;
        if (opt.range)
            r = {float((*opt.range)[0] - offset), float((*opt.range)[1] - offset)};
        else
            r = robustRange(v);
        const float lo = r[0], inv = r[1] != r[0] ? 1.0f / (r[1] - r[0]) : 1.0f;
        each([&](size_t i) { return sample(m, (v[i] - lo) * inv); });
    };
    switch (mode) {
        case ColorMode::Rgb:
            if (c.colors.size() == n)
                each([&](size_t i) { return Vec3f(c.colors[i][0], c.colors[i][1], c.colors[i][2]) * (1.0f / 255.0f); });
            break;
        case ColorMode::Elevation: {
            std::vector<float> z(n);
            for (size_t i = 0; i < n; ++i) z[i] = c.positions[i].z;
            // --range is in the file's coordinates: the origin shift applies to it too.
            mapped(z, c.origin[2], "viridis");
            break;
        }
        case ColorMode::Intensity:
            if (c.intensities.size() == n)
                mapped(c.intensities, 0, "grayscale");
            else if (c.colors.size() == n)  // grey value of the colours
                each([&](size_t i) {
                    return Vec3f((0.299f * c.colors[i][0] + 0.587f * c.colors[i][1] + 0.114f * c.colors[i][2]) /
                                 255.0f);
                });
            else
                throw Error(source, "--color intensity: the file has no intensity");
            break;
        case ColorMode::Classification:
            if (c.classes.size() != n) throw Error(source, "--color classification: the file has no classification");
            each([&](size_t i) { return classificationColor(c.classes[i]); });
            break;
        case ColorMode::Return: {
            if (c.returnNumbers.size() != n || c.returnCounts.size() != n)
                throw Error(source, "--color return: the file has no return numbers");
            // Single returns, first / intermediate / last of several.
            const Vec3f single = linear(60, 120, 220), first = linear(60, 190, 70), mid = linear(240, 200, 50),
                        last = linear(220, 60, 40);
            each([&](size_t i) {
                const int r = c.returnNumbers[i], k = c.returnCounts[i];
                if (k <= 1) return single;
                return r <= 1 ? first : r >= k ? last : mid;
            });
            break;
        }
        case ColorMode::Attribute: {
            const ScalarField* s = c.scalar(opt.attribute);
            if (!s) s = c.scalar("scalar_" + opt.attribute);
            if (s) {
                mapped(s->values, s->offset, "viridis");
            } else if (opt.attribute == "intensity" && c.intensities.size() == n) {
                mapped(c.intensities, 0, "viridis");
            } else {
                std::string names = c.intensities.size() == n ? "intensity" : "";
                for (const ScalarField& f : c.scalars) names += (names.empty() ? "" : ", ") + f.name;
                throw Error(source, "--color attr:" + opt.attribute + ": no such attribute (" +
                                        (names.empty() ? std::string("the file has none") : "the file has " + names) +
                                        ")");
            }
            break;
        }
        default:  // Lod, Normal: coloured at shading time
            break;
    }
    return out;
}

}  // namespace rtfact::points
