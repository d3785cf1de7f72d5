#include "python/settings_kwargs.h"

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "core/render/packet_dispatch.h"
#include "engine/setting_text.h"
#include "engine/usage_error.h"
#include "python/errors.h"

namespace py = pybind11;

namespace rtfact::python {

namespace {

using engine::SceneKind;

std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

double number(py::handle h, const std::string& name) {
    if (py::isinstance<py::bool_>(h) ||
        !(py::isinstance<py::float_>(h) || py::isinstance<py::int_>(h) || py::hasattr(h, "__float__")))
        throwValue(name, "expected a number, got " + py::repr(h).cast<std::string>());
    const double v = h.cast<double>();
    if (!std::isfinite(v)) throwValue(name, "expected a finite number, got " + py::repr(h).cast<std::string>());
    return v;
}

float numberIn(py::handle h, const std::string& name, double lo, double hi) {
    const double v = number(h, name);
    if (v < lo || v > hi)
        throwValue(name, "must be in [" + py::repr(py::float_(lo)).cast<std::string>() + ", " +
                             py::repr(py::float_(hi)).cast<std::string>() + "], got " +
                             py::repr(h).cast<std::string>());
    return float(v);
}

float positive(py::handle h, const std::string& name) {
    const double v = number(h, name);
    if (!(v > 0) || float(v) == 0.0f || !std::isfinite(float(v)))
        throwValue(name, "must be a positive number, got " + py::repr(h).cast<std::string>());
    return float(v);
}

int integerIn(py::handle h, const std::string& name, long lo, long hi) {
    if (py::isinstance<py::bool_>(h) || !py::isinstance<py::int_>(h))
        throwValue(name, "expected an integer, got " + py::repr(h).cast<std::string>());
    const long v = h.cast<long>();
    if (v < lo || v > hi)
        throwValue(name,
                   "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + std::to_string(v));
    return int(v);
}

std::string text(py::handle h, const std::string& name) {
    if (!py::isinstance<py::str>(h)) throwValue(name, "expected a string, got " + py::repr(h).cast<std::string>());
    return h.cast<std::string>();
}

std::string choice(py::handle h, const std::string& name, const std::vector<std::string>& table) {
    const std::string s = text(h, name);
    if (std::find(table.begin(), table.end(), s) == table.end())
        throwValue(name, "'" + s + "' is not one of " + joined(table));
    return s;
}

bool flag(py::handle h, const std::string& name) {
    if (!py::isinstance<py::bool_>(h))
        throwValue(name, "expected True or False, got " + py::repr(h).cast<std::string>());
    return h.cast<bool>();
}

// A string or a list of strings.
std::vector<std::string> texts(py::handle h, const std::string& name) {
    if (py::isinstance<py::str>(h)) return {h.cast<std::string>()};
    std::vector<std::string> out;
    if (!py::isinstance<py::sequence>(h)) throwValue(name, "expected a string or a list of strings");
    for (py::handle x : h.cast<py::sequence>()) out.push_back(text(x, name));
    return out;
}

Vec3f vec3Text(const std::string& s, const std::string& name) { return engine::parseVec3Text(s, name); }

std::pair<int, int> sizeArg(py::handle h) {
    if (py::isinstance<py::str>(h)) {
        const std::string s = h.cast<std::string>();
        int w = 0, hh = 0;
        char tail = 0;
        if (std::sscanf(s.c_str(), "%dx%d%c", &w, &hh, &tail) != 2 || w < 1 || hh < 1 || w > 16384 || hh > 16384)
            throwValue("size", "expected WxH or (w, h) with 1..16384 pixels each, got '" + s + "'");
        return {w, hh};
    }
    if (!py::isinstance<py::sequence>(h) || py::len(h) != 2)
        throwValue("size", "expected (width, height), got " + py::repr(h).cast<std::string>());
    const auto seq = h.cast<py::sequence>();
    return {integerIn(seq[0], "size", 1, 16384), integerIn(seq[1], "size", 1, 16384)};
}

// "axis:lo:hi" or {axis: (lo, hi)}: fractions of the axis.
void clipArg(py::handle h, engine::VolumeSettings& s) {
    if (py::isinstance<py::dict>(h)) {
        for (auto [k, v] : h.cast<py::dict>()) {
            const std::string axis = text(k, "clip");
            if (!py::isinstance<py::sequence>(v) || py::len(v) != 2) throwValue("clip", "expected {axis: (lo, hi)}");
            const auto seq = v.cast<py::sequence>();
            engine::applyClip(axis, float(number(seq[0], "clip")), float(number(seq[1], "clip")), s, "clip");
        }
        return;
    }
    for (const std::string& c : texts(h, "clip")) engine::applyClipText(c, s, "clip");
}

engine::LightSpec lightArg(const std::string& s) { return engine::parseLightText(s, "light"); }

surfaces::MeshMaterial materialArg(const std::string& spec) { return engine::parseMaterialText(spec, "material"); }

// The names each kind accepts besides the shared ones.
const std::set<std::string>& namesOf(SceneKind k) {
    static const std::set<std::string> points{"integrator", "color",         "lod",       "lod_quality", "normals",
                                              "radius",     "radius_factor", "leaf_size", "ao_samples",  "accel"};
    static const std::set<std::string> mesh{"integrator", "max_depth",  "light",    "material",
                                            "bvh",        "ao_samples", "secondary"};
    static const std::set<std::string> volume{
        "tf", "mode", "iso", "step", "window", "level", "clip", "no_skip", "no_adaptive_steps", "preintegrated"};
    static const std::set<std::string> spheres{"integrator"};
    switch (k) {
        case SceneKind::Points:
            return points;
        case SceneKind::Mesh:
            return mesh;
        case SceneKind::Volume:
            return volume;
        default:
            return spheres;
    }
}

const std::set<std::string>& sharedNames() {
    static const std::set<std::string> s{"size", "spp", "threads", "packet",   "eye",
                                         "at",   "up",  "fov",     "progress", "quiet"};
    return s;
}

void applyPoints(engine::PointSettings& s, const std::string& k, py::handle v) {
    if (k == "integrator") s.integrator = choice(v, k, engine::pointIntegrators());
    if (k == "color") s.color = points::parseColorMode(choice(v, k, {"rgb", "intensity", "lod", "normal"}));
    if (k == "lod") s.lod = py::isinstance<py::str>(v) ? choice(v, k, {"on", "off"}) == "on" : flag(v, k);
    if (k == "lod_quality") s.lodQuality = numberIn(v, k, 0.0, 64.0);
    if (k == "normals") s.normals = choice(v, k, {"auto", "estimate", "file"});
    if (k == "radius") s.radius = positive(v, k);
    if (k == "radius_factor") s.radiusFactor = numberIn(v, k, 1e-3, 1e3);
    if (k == "leaf_size") s.leafSize = integerIn(v, k, 1, 64);
    if (k == "accel") s.accel = choice(v, k, engine::pointAccels());
    if (k == "ao_samples") s.aoSamples = integerIn(v, k, 1, 256);
}

void applyMesh(engine::MeshSettings& s, const std::string& k, py::handle v) {
    if (k == "integrator") s.integrator = choice(v, k, engine::meshIntegrators());
    if (k == "max_depth") s.maxDepth = integerIn(v, k, 1, 64);
    if (k == "light")
        for (const std::string& l : texts(v, k)) s.lights.push_back(lightArg(l));
    if (k == "material") s.material = materialArg(text(v, k));
    if (k == "bvh") s.bvh = choice(v, k, {"sah", "kdtree"});
    if (k == "ao_samples") s.aoSamples = integerIn(v, k, 1, 1024);
    if (k == "secondary") s.secondary = choice(v, k, {"auto", "wide", "packet"});
}

void applyVolume(engine::VolumeSettings& s, const std::string& k, py::handle v) {
    if (k == "tf") s.tf = transferFunctionFrom(v);
    if (k == "mode") s.mode = choice(v, k, engine::volumeModes());
    if (k == "iso") s.iso = float(number(v, k));
    if (k == "step") s.step = numberIn(v, k, 0.01, 64.0);
    if (k == "window") s.window = positive(v, k);
    if (k == "level") s.level = float(number(v, k));
    if (k == "clip") clipArg(v, s);
    if (k == "no_skip") s.skipping = !flag(v, k);
    if (k == "no_adaptive_steps") s.adaptiveSteps = !flag(v, k);
    if (k == "preintegrated") s.preintegrated = flag(v, k);
}

}  // namespace

Vec3f vec3Arg(py::handle h, const std::string& name) {
    if (py::isinstance<py::str>(h)) return vec3Text(h.cast<std::string>(), name);
    if (!py::isinstance<py::sequence>(h) || py::len(h) != 3)
        throwValue(name, "expected 3 numbers, got " + py::repr(h).cast<std::string>());
    const auto seq = h.cast<py::sequence>();
    return {float(number(seq[0], name)), float(number(seq[1], name)), float(number(seq[2], name))};
}

RenderRequest renderRequest(SceneKind kind, const py::dict& kwargs) {
    RenderRequest r;
    r.frame.packet = 0;  // the kind's default, as the CLI
    const auto& names = namesOf(kind);
    for (auto [key, value] : kwargs) {
        const std::string k = key.cast<std::string>();
        if (!names.count(k) && !sharedNames().count(k)) {
            std::string known;
            for (const auto* set : {&sharedNames(), &names})
                for (const std::string& n : *set) known += (known.empty() ? "" : ", ") + n;
            throw py::type_error("unknown setting '" + k + "' for a " + engine::kindName(kind) +
                                 " scene (known: " + known + ")");
        }
        if (k == "size") std::tie(r.frame.width, r.frame.height) = sizeArg(value);
        if (k == "spp") r.spp = integerIn(value, k, 1, 1 << 20);
        if (k == "threads") r.frame.threads = integerIn(value, k, 0, 4096);
        if (k == "packet") {
            r.frame.packet = integerIn(value, k, 0, 256);
            if (r.frame.packet != 0 &&
                std::find(std::begin(kPacketSizes), std::end(kPacketSizes), r.frame.packet) == std::end(kPacketSizes))
                throwValue(k, "must be one of " + supportedPacketSizes());
        }
        if (k == "eye") r.eye = vec3Arg(value, k);
        if (k == "at") r.at = vec3Arg(value, k);
        if (k == "up") r.up = vec3Arg(value, k);
        if (k == "fov") r.fov = numberIn(value, k, 1.0, 179.0);
        if (k == "progress") r.frame.progress = flag(value, k);
        if (k == "quiet") r.frame.progress = !flag(value, k);
        switch (kind) {
            case SceneKind::Points:
                applyPoints(r.settings.points, k, value);
                break;
            case SceneKind::Mesh:
                applyMesh(r.settings.mesh, k, value);
                break;
            case SceneKind::Volume:
                applyVolume(r.settings.volume, k, value);
                break;
            default:
                if (k == "integrator") r.settings.spheres.integrator = choice(value, k, engine::spheresIntegrators());
        }
    }
    r.frame.target = "image";
    return r;
}

CameraFrame requestCamera(const engine::Scene& scene, const RenderRequest& r, const std::optional<CameraFrame>& camera,
                          bool cameraArgs) {
    if (camera) {
        if (cameraArgs) throw py::type_error("give either camera= or eye/at/up/fov, not both");
        return *camera;
    }
    const engine::DefaultView view = scene.defaultView(r.settings);
    const float aspect = float(r.frame.width) / float(r.frame.height);
    // As `rtfact --eye/--at/--up/--fov` (apps/rtfact/common_options.cpp).
    CameraFrame f = ::rtfact::fitCamera(view.focus, r.fov, aspect, view.viewDir, r.up.value_or(view.up));
    if (r.at) f.at = *r.at;
    if (r.eye)
        f.eye = *r.eye;
    else if (r.at)
        f.eye = *r.at + (f.eye - view.focus.center());
    if (r.up) f.up = *r.up;
    const Vec3f dir = f.at - f.eye;
    if (!(length(dir) > 0.0f)) throwValue("eye", "coincides with the camera target (at or the scene centre)");
    auto alongView = [&](Vec3f u) { return !(length(cross(normalize(dir), normalize(u))) > 1e-3f); };
    if (alongView(f.up)) {
        if (r.up) throwValue("up", "is parallel to the viewing direction");
        f.up = alongView(Vec3f(0, 1, 0)) ? Vec3f(0, 0, 1) : Vec3f(0, 1, 0);
    }
    return f;
}

engine::OpenOptions openOptions(const py::dict& kwargs) {
    engine::OpenOptions o;
    o.progress = false;
    o.volume.progress = false;
    for (auto [key, value] : kwargs) {
        const std::string k = key.cast<std::string>();
        if (k == "kind") {
            const std::string kind = choice(value, k, {"points", "mesh", "volume"});
            o.kind = kind == "points" ? SceneKind::Points : kind == "mesh" ? SceneKind::Mesh : SceneKind::Volume;
        } else if (k == "dims") {
            if (!py::isinstance<py::sequence>(value) || py::len(value) != 3)
                throwValue(k, "expected (x, y, z) voxel counts");
            std::array<int, 3> d{};
            for (size_t a = 0; a < 3; ++a) d[a] = integerIn(value.cast<py::sequence>()[a], k, 1, 1 << 20);
            o.volume.dims = d;
        } else if (k == "type") {
            o.volume.type = choice(value, k, {"u8", "u16", "i16", "f32"});
        } else if (k == "endian") {
            o.volume.endian = choice(value, k, {"little", "big"});
        } else if (k == "spacing") {
            const Vec3f s = vec3Arg(value, k);
            if (!(s.x > 0 && s.y > 0 && s.z > 0)) throwValue(k, "must be positive");
            o.volume.spacing = s;
        } else if (k == "header_skip") {
            o.volume.headerSkip = uint64_t(integerIn(value, k, 0, INT32_MAX));
        } else if (k == "grid") {
            o.volume.grid = text(value, k);
        } else if (k == "progress") {
            o.progress = flag(value, k);
        } else {
            throw py::type_error("unknown load option '" + k +
                                 "' (known: kind, dims, type, endian, spacing, header_skip, grid, progress)");
        }
    }
    return o;
}

volume::TransferFunction transferFunctionFrom(py::handle h) {
    volume::TransferFunction tf;
    try {
        if (py::isinstance<volume::TransferFunction>(h)) {
            tf = h.cast<volume::TransferFunction>();
        } else if (py::isinstance<py::str>(h)) {
            const std::string s = h.cast<std::string>();
            const auto presets = volume::transferFunctionPresets();
            if (std::find(presets.begin(), presets.end(), s) != presets.end()) return volume::transferFunctionPreset(s);
            if (s.size() < 5 || s.substr(s.size() - 5) != ".json")
                throwValue("tf", "'" + s + "' is neither a preset (" + joined(presets) + ") nor a .json file");
            return volume::loadTransferFunction(s);  // file problems: rtfact.Error
        } else if (py::isinstance<py::dict>(h)) {
            const std::string json = py::module_::import("json").attr("dumps")(h).cast<std::string>();
            return volume::parseTransferFunctionJson(json, "tf");
        } else if (py::isinstance<py::sequence>(h)) {
            tf.name = "list";
            size_t row = 0;
            for (py::handle r : h.cast<py::sequence>()) {
                if (!py::isinstance<py::sequence>(r) || py::len(r) != 5)
                    throwValue("tf", "row " + std::to_string(row) + ": expected (x, r, g, b, a)");
                const auto v = r.cast<py::sequence>();
                const float x = float(number(v[0], "tf"));
                tf.colors.push_back(
                    {x, Vec3f(float(number(v[1], "tf")), float(number(v[2], "tf")), float(number(v[3], "tf")))});
                tf.opacity.push_back({x, float(number(v[4], "tf"))});
                ++row;
            }
        } else {
            throwValue("tf", "expected a preset name, a .json path, a dict or a list of (x, r, g, b, a) rows");
        }
        tf.validate("tf");
    } catch (const engine::UsageError&) {
        throw;
    } catch (const Error& e) {
        // A bad TF given inline is a bad argument; a file's problems stay file errors.
        if (py::isinstance<py::str>(h)) throw;
        throw engine::UsageError("tf", e.what());
    }
    return tf;
}

}  // namespace rtfact::python
