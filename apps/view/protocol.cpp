#include "apps/view/protocol.h"

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "points/point_colors.h"
#include "points/point_prepare.h"

namespace rtfact::viewer {

using nlohmann::json;

namespace {

[[noreturn]] void bad(const std::string& what) { throw Error("message", what); }

const json& field(const json& j, const char* key) {
    if (!j.contains(key)) bad(std::string("missing \"") + key + "\"");
    return j[key];
}

double number(const json& j, const std::string& key, double lo, double hi) {
    if (!j.is_number()) bad("\"" + key + "\" must be a number");
    const double v = j.get<double>();
    if (!std::isfinite(v) || v < lo || v > hi)
        bad("\"" + key + "\" must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    return v;
}

int integer(const json& j, const std::string& key, int lo, int hi) {
    if (!j.is_number_integer()) bad("\"" + key + "\" must be an integer");
    const long long v = j.get<long long>();
    if (v < lo || v > hi) bad("\"" + key + "\" must be between " + std::to_string(lo) + " and " + std::to_string(hi));
    return int(v);
}

bool boolean(const json& j, const std::string& key) {
    if (!j.is_boolean()) bad("\"" + key + "\" must be true or false");
    return j.get<bool>();
}

// Coordinates beyond 1e30 overflow the camera's products.
Vec3f vec3(const json& j, const std::string& key, double lo = -1e30, double hi = 1e30) {
    if (!j.is_array() || j.size() != 3) bad("\"" + key + "\" must be an array of three numbers");
    return {float(number(j[0], key, lo, hi)), float(number(j[1], key, lo, hi)), float(number(j[2], key, lo, hi))};
}

std::string oneOf(const json& j, const std::string& key, const std::vector<std::string>& names) {
    if (!j.is_string()) bad("\"" + key + "\" must be a string");
    const std::string v = j.get<std::string>();
    if (std::find(names.begin(), names.end(), v) == names.end()) {
        std::string list;
        for (const std::string& n : names) list += (list.empty() ? "" : "|") + n;
        bad("\"" + key + "\" must be one of " + list);
    }
    return v;
}

void onlyKeys(const json& j, const std::string& what, std::initializer_list<const char*> keys) {
    if (!j.is_object()) bad("\"" + what + "\" must be an object");
    for (auto it = j.begin(); it != j.end(); ++it)
        if (std::none_of(keys.begin(), keys.end(), [&](const char* k) { return it.key() == k; }))
            bad("unknown field \"" + it.key() + "\" in " + what);
}

CameraFrame parseCamera(const json& j) {
    CameraFrame c;
    c.eye = vec3(field(j, "eye"), "eye");
    c.at = vec3(field(j, "at"), "at");
    c.up = vec3(field(j, "up"), "up");
    c.fovDeg = float(number(field(j, "fov"), "fov", 1.0, 170.0));
    const Vec3f view = c.at - c.eye;
    if (!(length(view) > 0.0f) || !std::isfinite(length(view))) bad("\"eye\" and \"at\" coincide");
    if (!(length(c.up) > 0.0f)) bad("\"up\" must not be zero");
    if (!(length(cross(normalize(view), normalize(c.up))) > 1e-3f)) bad("\"up\" is parallel to the view direction");
    return c;
}

// The colour modes the page offers (every cloud has what these colour by).
const std::vector<std::string> kColorModes = {"auto", "rgb", "elevation", "intensity", "lod", "normal"};
const std::vector<std::string> kMaterials = {"default", "lambert", "mirror", "glass"};

void applyPoints(const json& p, engine::PointSettings& s) {
    onlyKeys(p, "points", {"integrator", "color", "lod", "lodQuality", "radiusFactor", "aoSamples"});
    if (p.contains("integrator")) s.integrator = oneOf(p["integrator"], "integrator", engine::pointIntegrators());
    if (p.contains("color")) s.color = points::parseColorMode(oneOf(p["color"], "color", kColorModes));
    if (p.contains("lod")) s.lod = boolean(p["lod"], "lod");
    if (p.contains("lodQuality")) s.lodQuality = float(number(p["lodQuality"], "lodQuality", 0.0, 64.0));
    if (p.contains("radiusFactor")) s.radiusFactor = float(number(p["radiusFactor"], "radiusFactor", 1e-3, 1e3));
    if (p.contains("aoSamples")) s.aoSamples = integer(p["aoSamples"], "aoSamples", 1, 256);
}

void applyVolume(const json& v, engine::VolumeSettings& s) {
    onlyKeys(v, "volume", {"mode", "tf", "window", "level", "step", "clipLo", "clipHi", "iso", "preintegrated"});
    if (v.contains("mode")) s.mode = oneOf(v["mode"], "mode", engine::volumeModes());
    if (v.contains("tf")) {
        const json& t = v["tf"];
        if (t.is_null()) {
            s.tf.reset();
        } else if (t.is_string()) {
            s.tf = volume::transferFunctionPreset(oneOf(t, "tf", volume::transferFunctionPresets()));
        } else if (t.is_object()) {
            // Our TF format (volume/transfer_function.h); its own checks name the problem.
            try {
                volume::TransferFunction tf = volume::parseTransferFunctionJson(t.dump(), "tf");
                tf.validate("tf");
                s.tf = tf;
            } catch (const Error& e) {
                bad(e.message());
            }
        } else {
            bad("\"tf\" must be a preset name, a transfer function object or null");
        }
    }
    auto optionalNumber = [&](const char* key, std::optional<float>& out, double lo, double hi) {
        if (!v.contains(key)) return;
        if (v[key].is_null())
            out.reset();
        else
            out = float(number(v[key], key, lo, hi));
    };
    optionalNumber("window", s.window, 1e-30, 1e30);
    optionalNumber("level", s.level, -1e30, 1e30);
    optionalNumber("iso", s.iso, -1e30, 1e30);
    if (v.contains("step")) s.step = float(number(v["step"], "step", 0.01, 64.0));
    if (v.contains("preintegrated")) s.preintegrated = boolean(v["preintegrated"], "preintegrated");
    if (v.contains("clipLo")) s.clipLo = vec3(v["clipLo"], "clipLo", 0.0, 1.0);
    if (v.contains("clipHi")) s.clipHi = vec3(v["clipHi"], "clipHi", 0.0, 1.0);
    for (int a = 0; a < 3; ++a)
        if (!(s.clipLo[a] < s.clipHi[a])) bad("\"clipLo\" must be below \"clipHi\" on every axis");
}

void applyMesh(const json& m, engine::MeshSettings& s) {
    onlyKeys(m, "mesh", {"integrator", "material", "aoSamples", "maxDepth", "light"});
    if (m.contains("integrator")) s.integrator = oneOf(m["integrator"], "integrator", engine::meshIntegrators());
    if (m.contains("material")) {
        const std::string k = oneOf(m["material"], "material", kMaterials);
        if (k == "default")
            s.material.reset();
        else
            s.material = k == "lambert"  ? engine::lambertMaterial()
                         : k == "mirror" ? engine::mirrorMaterial()
                                         : engine::glassMaterial();
    }
    if (m.contains("aoSamples")) s.aoSamples = integer(m["aoSamples"], "aoSamples", 1, 256);
    if (m.contains("maxDepth")) s.maxDepth = integer(m["maxDepth"], "maxDepth", 1, 64);
    if (m.contains("light")) {
        const json& l = m["light"];
        s.lights.clear();
        if (!l.is_null()) {
            // One directional light (the page's light-direction control); null: the default key light.
            const Vec3f d = vec3(l, "light", -1e6, 1e6);
            if (!(length(d) > 0.0f)) bad("\"light\" must not be zero");
            s.lights.push_back({engine::LightSpec::Kind::Directional, d});
        }
    }
}

}  // namespace

ClientMessage parseMessage(std::string_view text) {
    if (text.size() > kMaxMessageBytes)
        bad("too long (" + std::to_string(text.size()) + " bytes, at most " + std::to_string(kMaxMessageBytes) + ")");
    json j = json::parse(text.begin(), text.end(), nullptr, false);
    if (j.is_discarded()) bad("not valid JSON");
    if (!j.is_object()) bad("must be a JSON object");
    const std::string type = oneOf(field(j, "type"), "type",
                                   {"camera", "ack", "resize", "settings", "fit", "reset", "screenshot", "format"});
    ClientMessage m;
    using T = ClientMessage::Type;
    if (type == "camera") {
        onlyKeys(j, "camera", {"type", "eye", "at", "up", "fov", "moving"});
        m.type = T::Camera;
        m.camera = parseCamera(j);
        if (j.contains("moving")) m.moving = boolean(j["moving"], "moving");
    } else if (type == "ack") {
        onlyKeys(j, "ack", {"type", "frame"});
        m.type = T::Ack;
        const json& f = field(j, "frame");
        if (!f.is_number_unsigned()) bad("\"frame\" must be a frame id");
        m.frame = f.get<uint64_t>();
    } else if (type == "resize") {
        onlyKeys(j, "resize", {"type", "width", "height"});
        m.type = T::Resize;
        m.width = integer(field(j, "width"), "width", 16, kMaxImageSide);
        m.height = integer(field(j, "height"), "height", 16, kMaxImageSide);
    } else if (type == "settings") {
        onlyKeys(j, "settings", {"type", "points", "volume", "mesh"});
        m.type = T::Settings;
        m.settings = j;
        m.settings.erase("type");
        if (m.settings.size() != 1) bad("\"settings\" takes exactly one of points, volume, mesh");
    } else if (type == "format") {
        onlyKeys(j, "format", {"type", "lossless", "quality"});
        m.type = T::Format;
        if (j.contains("lossless")) m.lossless = boolean(j["lossless"], "lossless");
        if (j.contains("quality")) m.quality = integer(j["quality"], "quality", 1, 100);
    } else {
        onlyKeys(j, type, {"type"});
        m.type = type == "fit" ? T::Fit : type == "reset" ? T::Reset : T::Screenshot;
    }
    return m;
}

void applySettings(const json& patch, engine::SceneKind kind, engine::Settings& s) {
    engine::Settings next = s;
    using K = engine::SceneKind;
    const char* key = kind == K::Points ? "points" : kind == K::Volume ? "volume" : kind == K::Mesh ? "mesh" : "";
    if (!patch.is_object() || patch.size() != 1 || !patch.contains(key))
        bad(std::string("this scene takes \"") + (*key ? key : "no") + "\" settings");
    if (kind == K::Points) applyPoints(patch[key], next.points);
    if (kind == K::Volume) applyVolume(patch[key], next.volume);
    if (kind == K::Mesh) applyMesh(patch[key], next.mesh);
    s = next;
}

json cameraJson(const CameraFrame& c) {
    return {{"eye", {c.eye.x, c.eye.y, c.eye.z}},
            {"at", {c.at.x, c.at.y, c.at.z}},
            {"up", {c.up.x, c.up.y, c.up.z}},
            {"fov", c.fovDeg}};
}

namespace {
json tfJson(const volume::TransferFunction& tf) {
    json colors = json::array(), opacity = json::array();
    for (const volume::ColorPoint& p : tf.colors) colors.push_back({p.x, p.rgb.x, p.rgb.y, p.rgb.z});
    for (const volume::OpacityPoint& p : tf.opacity) opacity.push_back({p.x, p.a});
    return {
        {"name", tf.name}, {"space", tf.normalized ? "normalized" : "data"}, {"colors", colors}, {"opacity", opacity}};
}
}  // namespace

json settingsJson(const engine::Settings& s, engine::SceneKind kind) {
    using K = engine::SceneKind;
    if (kind == K::Points) {
        const engine::PointSettings& p = s.points;
        return {{"integrator", p.integrator}, {"color", points::colorModeName(p.color)}, {"lod", p.lod},
                {"lodQuality", p.lodQuality}, {"radiusFactor", p.radiusFactor},          {"aoSamples", p.aoSamples}};
    }
    if (kind == K::Volume) {
        const engine::VolumeSettings& v = s.volume;
        json j = {{"mode", v.mode},
                  {"step", v.step},
                  {"preintegrated", v.preintegrated},
                  {"clipLo", {v.clipLo.x, v.clipLo.y, v.clipLo.z}},
                  {"clipHi", {v.clipHi.x, v.clipHi.y, v.clipHi.z}}};
        j["tf"] = v.tf ? tfJson(*v.tf) : json(nullptr);
        j["window"] = v.window ? json(*v.window) : json(nullptr);
        j["level"] = v.level ? json(*v.level) : json(nullptr);
        j["iso"] = v.iso ? json(*v.iso) : json(nullptr);
        return j;
    }
    if (kind == K::Mesh) {
        const engine::MeshSettings& m = s.mesh;
        json j = {{"integrator", m.integrator},
                  {"material", m.material ? m.material->name : std::string("default")},
                  {"aoSamples", m.aoSamples},
                  {"maxDepth", m.maxDepth}};
        j["light"] = m.lights.size() == 1 && m.lights[0].kind == engine::LightSpec::Kind::Directional
                         ? json{m.lights[0].v.x, m.lights[0].v.y, m.lights[0].v.z}
                         : json(nullptr);
        return j;
    }
    return json::object();
}

json choicesJson(engine::SceneKind kind) {
    using K = engine::SceneKind;
    if (kind == K::Points) return {{"integrator", engine::pointIntegrators()}, {"color", kColorModes}};
    if (kind == K::Volume) return {{"mode", engine::volumeModes()}, {"tf", volume::transferFunctionPresets()}};
    if (kind == K::Mesh) return {{"integrator", engine::meshIntegrators()}, {"material", kMaterials}};
    return json::object();
}

json transferJson(const engine::VolumeTransferInfo& t) {
    const volume::ValueHistogram& h = t.histogram;
    return {{"lo", h.binLo(0)},
            {"hi", h.binLo(h.bins.size())},
            {"bins", h.bins},
            {"tf", tfJson(t.tf)},
            {"window", {t.window.first, t.window.second}}};
}

json errorJson(const std::string& message) { return {{"type", "error"}, {"message", message}}; }

}  // namespace rtfact::viewer
