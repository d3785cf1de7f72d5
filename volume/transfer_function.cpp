#include "volume/transfer_function.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/render/srgb.h"
#include "core/util/error.h"
#include "core/util/input_file.h"

namespace rtfact::volume {

namespace {

template <class P, class F>
auto interpolate(const std::vector<P>& pts, float x, F get) -> decltype(get(pts[0])) {
    if (pts.empty()) return decltype(get(pts[0]))();
    if (x <= pts.front().x) return get(pts.front());
    if (x >= pts.back().x) return get(pts.back());
    auto it = std::upper_bound(pts.begin(), pts.end(), x, [](float v, const P& p) { return v < p.x; });
    const P& b = *it;
    const P& a = *(it - 1);
    const float w = b.x > a.x ? (x - a.x) / (b.x - a.x) : 1.0f;
    return get(a) * (1.0f - w) + get(b) * w;
}

TransferFunction make(const char* name, std::vector<ColorPoint> c, std::vector<OpacityPoint> o,
                      std::optional<std::pair<float, float>> hu = std::nullopt) {
    TransferFunction tf;
    tf.name = name;
    tf.colors = std::move(c);
    tf.opacity = std::move(o);
    tf.huWindow = hu;
    return tf;
}

// Colour maps get a linear opacity ramp so that they are usable for DVR directly.
std::vector<OpacityPoint> ramp(float lo = 0.1f, float hi = 0.6f) { return {{0.0f, 0.0f}, {lo, 0.0f}, {1.0f, hi}}; }

}  // namespace

Vec3f TransferFunction::color(float x) const {
    return interpolate(colors, x, [](const ColorPoint& p) { return p.rgb; });
}
float TransferFunction::alpha(float x) const {
    return interpolate(opacity, x, [](const OpacityPoint& p) { return p.a; });
}

void TransferFunction::validate(const std::string& source) const {
    if (colors.empty()) throw Error(source, "transfer function has no colour points");
    if (opacity.empty()) throw Error(source, "transfer function has no opacity points");
    for (size_t i = 0; i < colors.size(); ++i) {
        const auto& p = colors[i];
        if (!std::isfinite(p.x) || !isFinite(p.rgb))
            throw Error(source, "transfer function colour point " + std::to_string(i) + " is not finite");
        if (i && p.x < colors[i - 1].x) throw Error(source, "transfer function colour points are not sorted by value");
        for (int c = 0; c < 3; ++c)
            if (p.rgb[c] < 0 || p.rgb[c] > 1)
                throw Error(source, "transfer function colour point " + std::to_string(i) + " is outside [0, 1]");
    }
    for (size_t i = 0; i < opacity.size(); ++i) {
        const auto& p = opacity[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.a))
            throw Error(source, "transfer function opacity point " + std::to_string(i) + " is not finite");
        if (i && p.x < opacity[i - 1].x)
            throw Error(source, "transfer function opacity points are not sorted by value");
        if (p.a < 0 || p.a > 1)
            throw Error(source, "transfer function opacity point " + std::to_string(i) + " is outside [0, 1]");
    }
}

std::vector<std::string> transferFunctionPresets() {
    return {"ct-bone", "ct-skin", "ct-muscle", "mr-default", "grayscale", "viridis", "inferno", "cool-warm"};
}

TransferFunction transferFunctionPreset(const std::string& name) {
    // CT presets: normalized over [-1000, 2000] HU (air .. dense bone).
    const std::pair<float, float> hu{-1000.0f, 2000.0f};
    auto H = [](float h) { return (h + 1000.0f) / 3000.0f; };
    if (name == "ct-bone")
        return make("ct-bone",
                    {{H(150), {0.55f, 0.25f, 0.15f}},
                     {H(300), {0.88f, 0.76f, 0.6f}},
                     {H(700), {1.0f, 0.97f, 0.9f}},
                     {1.0f, {1, 1, 1}}},
                    {{0.0f, 0.0f}, {H(150), 0.0f}, {H(350), 0.35f}, {H(900), 0.8f}, {1.0f, 0.9f}}, hu);
    if (name == "ct-skin")
        return make("ct-skin",
                    {{H(-600), {0.7f, 0.45f, 0.35f}},
                     {H(-200), {0.95f, 0.75f, 0.62f}},
                     {H(200), {0.98f, 0.9f, 0.8f}},
                     {1.0f, {1, 1, 1}}},
                    {{0.0f, 0.0f}, {H(-600), 0.0f}, {H(-400), 0.08f}, {H(100), 0.12f}, {H(300), 0.6f}, {1.0f, 0.85f}},
                    hu);
    if (name == "ct-muscle")
        return make("ct-muscle",
                    {{H(-100), {0.55f, 0.15f, 0.1f}},
                     {H(40), {0.8f, 0.25f, 0.2f}},
                     {H(250), {0.95f, 0.85f, 0.75f}},
                     {1.0f, {1, 1, 1}}},
                    {{0.0f, 0.0f}, {H(-50), 0.0f}, {H(40), 0.12f}, {H(150), 0.05f}, {H(300), 0.5f}, {1.0f, 0.85f}}, hu);
    if (name == "mr-default")
        return make(
            "mr-default",
            {{0.0f, {0.0f, 0.0f, 0.0f}}, {0.3f, {0.55f, 0.45f, 0.4f}}, {0.7f, {0.9f, 0.85f, 0.8f}}, {1.0f, {1, 1, 1}}},
            {{0.0f, 0.0f}, {0.15f, 0.0f}, {0.4f, 0.06f}, {0.7f, 0.25f}, {1.0f, 0.6f}});
    if (name == "grayscale") return make("grayscale", {{0.0f, {0, 0, 0}}, {1.0f, {1, 1, 1}}}, ramp(0.05f, 0.5f));
    if (name == "viridis")
        return make("viridis",
                    {{0.0f, {0.267f, 0.005f, 0.329f}},
                     {0.25f, {0.229f, 0.322f, 0.546f}},
                     {0.5f, {0.128f, 0.567f, 0.551f}},
                     {0.75f, {0.369f, 0.789f, 0.383f}},
                     {1.0f, {0.993f, 0.906f, 0.144f}}},
                    ramp());
    if (name == "inferno")
        return make("inferno",
                    {{0.0f, {0.001f, 0.0f, 0.014f}},
                     {0.25f, {0.341f, 0.062f, 0.429f}},
                     {0.5f, {0.735f, 0.216f, 0.330f}},
                     {0.75f, {0.978f, 0.557f, 0.035f}},
                     {1.0f, {0.988f, 0.998f, 0.645f}}},
                    ramp());
    if (name == "cool-warm")
        return make(
            "cool-warm",
            {{0.0f, {0.230f, 0.299f, 0.754f}}, {0.5f, {0.865f, 0.865f, 0.865f}}, {1.0f, {0.706f, 0.016f, 0.150f}}},
            ramp());
    std::string list;
    for (auto& p : transferFunctionPresets()) list += (list.empty() ? "" : ", ") + p;
    throw Error("--tf", "unknown transfer function '" + name + "' (presets: " + list + ", or a .json file)");
}

TransferFunction parseTransferFunctionJson(const std::string& text, const std::string& source) {
    using nlohmann::json;
    json j;
    try {
        j = json::parse(text);
    } catch (const json::exception& e) {
        throw Error(source, std::string("invalid JSON: ") + e.what());
    }
    auto num = [&](const json& v, const char* what) -> float {
        if (!v.is_number()) throw Error(source, std::string("expected a number in ") + what);
        return v.get<float>();
    };
    TransferFunction tf;
    try {
        if (j.is_array()) {
            if (j.empty() || !j[0].is_object()) throw Error(source, "expected a ParaView preset (array of objects)");
            j = j[0];
        }
        if (!j.is_object()) throw Error(source, "expected a JSON object");
        if (j.contains("RGBPoints")) {
            // ParaView preset: RGBPoints = [x, r, g, b, ...], Points = [x, a, mid, sharp, ...];
            // rescaled to [0, 1] like ParaView rescales presets to the data range.
            tf.name = j.value("Name", std::string("paraview"));
            const json& rp = j["RGBPoints"];
            if (!rp.is_array() || rp.size() < 8 || rp.size() % 4 != 0)
                throw Error(source, "RGBPoints must hold groups of 4 numbers (x r g b), at least 2");
            for (size_t i = 0; i < rp.size(); i += 4)
                tf.colors.push_back(
                    {num(rp[i], "RGBPoints"),
                     {num(rp[i + 1], "RGBPoints"), num(rp[i + 2], "RGBPoints"), num(rp[i + 3], "RGBPoints")}});
            if (j.contains("Points")) {
                const json& op = j["Points"];
                if (!op.is_array() || op.size() < 8 || op.size() % 4 != 0)
                    throw Error(source, "Points must hold groups of 4 numbers (x a mid sharp), at least 2");
                for (size_t i = 0; i < op.size(); i += 4)
                    tf.opacity.push_back({num(op[i], "Points"), num(op[i + 1], "Points")});
            }
            float lo = tf.colors.front().x, hi = tf.colors.back().x;
            if (!(hi > lo)) throw Error(source, "RGBPoints span an empty range");
            for (auto& p : tf.colors) p.x = (p.x - lo) / (hi - lo);
            if (tf.opacity.empty())
                tf.opacity = ramp();
            else {
                const float olo = tf.opacity.front().x, ohi = tf.opacity.back().x;
                for (auto& p : tf.opacity) p.x = ohi > olo ? (p.x - olo) / (ohi - olo) : 0.0f;
            }
            tf.normalized = true;
        } else {
            // Ours: {"name", "space": "normalized"|"data", "colors": [[x,r,g,b]...], "opacity": [[x,a]...]}
            tf.name = j.value("name", std::string("custom"));
            const std::string space = j.value("space", std::string("normalized"));
            if (space != "normalized" && space != "data")
                throw Error(source, "\"space\" must be \"normalized\" or \"data\"");
            tf.normalized = space == "normalized";
            if (!j.contains("colors") || !j["colors"].is_array())
                throw Error(source, "missing \"colors\" array ([[x, r, g, b], ...])");
            if (!j.contains("opacity") || !j["opacity"].is_array())
                throw Error(source, "missing \"opacity\" array ([[x, a], ...])");
            for (const json& p : j["colors"]) {
                if (!p.is_array() || p.size() != 4) throw Error(source, "each colour point must be [x, r, g, b]");
                tf.colors.push_back(
                    {num(p[0], "colors"), {num(p[1], "colors"), num(p[2], "colors"), num(p[3], "colors")}});
            }
            for (const json& p : j["opacity"]) {
                if (!p.is_array() || p.size() != 2) throw Error(source, "each opacity point must be [x, a]");
                tf.opacity.push_back({num(p[0], "opacity"), num(p[1], "opacity")});
            }
        }
    } catch (const json::exception& e) {
        throw Error(source, std::string("bad transfer function: ") + e.what());
    }
    tf.validate(source);
    return tf;
}

TransferFunction loadTransferFunction(const std::string& path) {
    requireRegularFile(path);  // a FIFO would block the open
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error(path, "cannot open transfer function file");
    f.seekg(0, std::ios::end);
    const auto sz = f.tellg();
    if (sz > (16 << 20)) throw Error(path, "transfer function file is too large");
    f.seekg(0);
    std::stringstream ss;
    ss << f.rdbuf();
    return parseTransferFunctionJson(ss.str(), path);
}

TransferFunction resolveTransferFunction(const std::string& s) {
    if (s.size() > 5 && s.substr(s.size() - 5) == ".json") return loadTransferFunction(s);
    return transferFunctionPreset(s);
}

std::pair<float, float> resolveWindow(const TransferFunction& tf, float dataLo, float dataHi,
                                      std::optional<float> window, std::optional<float> level) {
    if (!tf.normalized) return {0.0f, 1.0f};  // points already in data units
    if (window || level) {
        const float w = window ? *window : dataHi - dataLo;
        const float l = level ? *level : 0.5f * (dataLo + dataHi);
        if (!(w > 0)) throw Error("--window", "window width must be positive");
        return {l - 0.5f * w, l + 0.5f * w};
    }
    if (tf.huWindow && dataLo <= -500.0f) return *tf.huWindow;
    if (!(dataHi > dataLo)) return {dataLo, dataLo + 1.0f};
    return {dataLo, dataHi};
}

int TFTable::index(float v) const {
    const float f = (v - lo) / (hi - lo) * float(size - 1) + 0.5f;
    if (!(f > 0)) return 0;
    return std::min(size - 1, int(f));
}

bool TFTable::visible(float vlo, float vhi) const {
    int i0 = index(vlo), i1 = index(vhi);
    if (i0 > i1) std::swap(i0, i1);
    return visiblePrefix[size_t(i1) + 1] - visiblePrefix[size_t(i0)] > 0;
}

TFTable buildTable(const TransferFunction& tf, std::pair<float, float> window, float stepVoxels, int size) {
    TFTable t;
    t.size = std::max(size, 2);
    // Points in data units: the table spans their range.
    if (!tf.normalized) {
        window = {std::min(tf.colors.front().x, tf.opacity.front().x),
                  std::max(tf.colors.back().x, tf.opacity.back().x)};
        if (!(window.second > window.first)) window.second = window.first + 1.0f;
    }
    t.lo = window.first;
    t.hi = window.second;
    t.r.resize(size_t(t.size));
    t.g.resize(size_t(t.size));
    t.b.resize(size_t(t.size));
    t.a.resize(size_t(t.size));
    t.visiblePrefix.assign(size_t(t.size) + 1, 0);
    for (int i = 0; i < t.size; ++i) {
        const float u = float(i) / float(t.size - 1);
        const float x = tf.normalized ? u : t.lo + u * (t.hi - t.lo);
        const Vec3f c = tf.color(x);
        const float a = std::clamp(tf.alpha(x), 0.0f, 1.0f);
        t.r[size_t(i)] = srgbToLinear(c.x);
        t.g[size_t(i)] = srgbToLinear(c.y);
        t.b[size_t(i)] = srgbToLinear(c.z);
        t.a[size_t(i)] = a >= 1.0f ? 1.0f : 1.0f - std::pow(1.0f - a, stepVoxels);
        t.visiblePrefix[size_t(i) + 1] = t.visiblePrefix[size_t(i)] + (t.a[size_t(i)] > 0.0f ? 1 : 0);
    }
    return t;
}

}  // namespace rtfact::volume
