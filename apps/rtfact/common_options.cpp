#include "apps/rtfact/common_options.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <sstream>

#include "core/render/packet_dispatch.h"
#include "core/util/progress.h"

namespace rtfact::app {

namespace {
std::string shortNumber(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}
// Parses the whole text as a double; nullopt when it is not a number.
std::optional<double> parseNumber(const std::string& text) {
    if (text.empty()) return std::nullopt;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size()) return std::nullopt;
    return v;
}
CLI::Validator numberValidator(std::function<std::string(double)> check, std::string description) {
    return CLI::Validator(
        [check = std::move(check)](std::string& text) -> std::string {
            const std::optional<double> v = parseNumber(text);
            if (!v) return "expected a number, got '" + text + "'";
            if (!std::isfinite(*v)) return "expected a finite number, got '" + text + "'";
            // The options are floats: 1e300 would become Inf and 1e-50 zero after the check.
            if (!std::isfinite(float(*v))) return "is too large for a float, got '" + text + "'";
            if (*v != 0 && float(*v) == 0.0f) return "is too small for a float, got '" + text + "'";
            return check(*v);
        },
        std::move(description));
}
}  // namespace

CLI::Validator finiteRange(double lo, double hi) {
    const std::string range = shortNumber(lo) + " to " + shortNumber(hi);
    return numberValidator(
        [lo, hi, range](double v) {
            return v < lo || v > hi ? "must be between " + range + ", got " + shortNumber(v) : std::string();
        },
        "NUMBER in [" + range + "]");
}

CLI::Validator positiveFinite() {
    return numberValidator(
        [](double v) { return v > 0 ? std::string() : "must be greater than 0, got " + shortNumber(v); }, "POSITIVE");
}

CLI::Validator finiteNumber() {
    return numberValidator([](double) { return std::string(); }, "NUMBER");
}

Vec3f parseVec3(const std::string& text, const std::string& option) {
    Vec3f v;
    std::stringstream ss(text);
    std::string part;
    int i = 0;
    while (std::getline(ss, part, ',')) {
        if (i >= 3) break;
        try {
            size_t used = 0;
            v[i] = std::stof(part, &used);
            if (used != part.size() || !std::isfinite(v[i])) throw std::invalid_argument(part);
        } catch (const std::exception&) {
            throw CLI::ValidationError(option, "expected three numbers x,y,z, got '" + text + "'");
        }
        ++i;
    }
    if (i != 3 || std::count(text.begin(), text.end(), ',') != 2)
        throw CLI::ValidationError(option, "expected three numbers x,y,z, got '" + text + "'");
    return v;
}

std::pair<int, int> parseSize(const std::string& text) {
    const auto x = text.find_first_of("xX");
    auto bad = [&] {
        return CLI::ValidationError("--size", "expected WxH with 1..16384 pixels each, got '" + text + "'");
    };
    if (x == std::string::npos) throw bad();
    int w = 0, h = 0;
    try {
        size_t uw = 0, uh = 0;
        const std::string ws = text.substr(0, x), hs = text.substr(x + 1);
        w = std::stoi(ws, &uw);
        h = std::stoi(hs, &uh);
        if (uw != ws.size() || uh != hs.size()) throw bad();
    } catch (const CLI::ValidationError&) {
        throw;
    } catch (const std::exception&) {
        throw bad();
    }
    if (w < 1 || h < 1 || w > 16384 || h > 16384) throw bad();
    return {w, h};
}

void CommonOptions::addTo(CLI::App& cmd, const std::string& defaultOut) {
    out = defaultOut;
    cmd.add_option("-o,--out", out, "Output image (.png .exr .tif .jpg)")->capture_default_str();
    cmd.add_option("--size", size, "Image size WxH")->capture_default_str();
    cmd.add_option("--eye", eye, "Camera position x,y,z (default: fitted to the scene)");
    cmd.add_option("--at", at, "Camera target x,y,z (default: scene centre)");
    cmd.add_option("--up", up, "Camera up vector x,y,z");
    cmd.add_option("--fov", fov, "Vertical field of view in degrees")
        ->capture_default_str()
        ->check(finiteRange(1.0, 170.0));
    cmd.add_option("--threads", threads, "Render threads (0: all cores)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1024));
    cmd.add_option("--packet", packet, "Rays per packet (" + supportedPacketSizes() + ")")->capture_default_str();
    cmd.add_option("--spp", spp, "Samples per pixel")->capture_default_str()->check(CLI::Range(1, 1 << 20));
    cmd.add_flag("--quiet", quiet, "No progress bars");
    cmd.add_flag("--stats", stats, "Print key=value statistics at the end");
    cmd.add_option("--distribute", distribute,
                   "Under mpirun: image (every rank loads the scene, tiles are shared) or data (volumes: each "
                   "rank loads a slab; default: image when the data fits every rank)")
        ->check(CLI::IsMember({"image", "data"}));
}

void CommonOptions::finalize() {
    std::tie(width, height) = parseSize(size);
    if (!eye.empty()) eyeV = parseVec3(eye, "--eye");
    if (!at.empty()) atV = parseVec3(at, "--at");
    if (!up.empty()) upV = parseVec3(up, "--up");
    bool ok = false;
    dispatchPacketSize(packet, [&]<int N>() { ok = true; });
    if (!ok) throw CLI::ValidationError("--packet", "must be one of " + supportedPacketSizes());
    if (eyeV && atV && length(*eyeV - *atV) == 0.0f) throw CLI::ValidationError("--eye", "eye and --at coincide");
    if (upV && length(*upV) == 0.0f) throw CLI::ValidationError("--up", "must not be zero");
    setProgressEnabled(!quiet);
}

CameraFrame CommonOptions::frame(const AABB& bounds, Vec3f viewDir, Vec3f upDefault) const {
    const float aspect = float(width) / float(height);
    CameraFrame f = fitCamera(bounds, fov, aspect, viewDir, upV.value_or(upDefault));
    if (atV) f.at = *atV;
    if (eyeV) {
        f.eye = *eyeV;
    } else if (atV) {
        f.eye = *atV + (f.eye - bounds.center());
    }
    if (upV) f.up = *upV;
    // An eye on its target or an up vector along the view leaves the camera without axes
    // (a NaN image): the user's options are errors, the default up is replaced.
    const Vec3f view = f.at - f.eye;
    if (!(length(view) > 0.0f))
        throw CLI::ValidationError("--eye", "coincides with the camera target (--at or the scene centre)");
    auto alongView = [&](Vec3f u) { return !(length(cross(normalize(view), normalize(u))) > 1e-3f); };
    if (alongView(f.up)) {
        if (upV) throw CLI::ValidationError("--up", "is parallel to the viewing direction");
        f.up = alongView(Vec3f(0, 1, 0)) ? Vec3f(0, 0, 1) : Vec3f(0, 1, 0);
    }
    return f;
}

}  // namespace rtfact::app
