#include "engine/setting_text.h"

#include <cmath>
#include <cstdio>

#include "engine/usage_error.h"

namespace rtfact::engine {

Vec3f parseVec3Text(const std::string& text, const std::string& option) {
    float v[3];
    char tail = 0;
    if (std::sscanf(text.c_str(), "%f,%f,%f%c", &v[0], &v[1], &v[2], &tail) != 3 || !std::isfinite(v[0]) ||
        !std::isfinite(v[1]) || !std::isfinite(v[2]))
        throw UsageError(option, "expected x,y,z with three finite numbers, got '" + text + "'");
    return {v[0], v[1], v[2]};
}

LightSpec parseLightText(const std::string& text, const std::string& option) {
    const size_t c = text.find(':');
    const std::string kind = c == std::string::npos ? "" : text.substr(0, c);
    if (kind == "point") return {LightSpec::Kind::Point, parseVec3Text(text.substr(c + 1), option)};
    if (kind == "dir") return {LightSpec::Kind::Directional, parseVec3Text(text.substr(c + 1), option)};
    throw UsageError(option, "expected point:x,y,z or dir:x,y,z, got '" + text + "'");
}

surfaces::MeshMaterial parseMaterialText(const std::string& text, const std::string& option) {
    const size_t c = text.find(':');
    const std::string kind = text.substr(0, c), arg = c == std::string::npos ? "" : text.substr(c + 1);
    auto colour = [&]() -> std::optional<Vec3f> {
        if (arg.empty()) return std::nullopt;
        return parseVec3Text(arg, option);
    };
    if (kind == "lambert") return lambertMaterial(colour());
    if (kind == "mirror") return mirrorMaterial(colour());
    if (kind == "glass") {
        float ior = 1.5f;
        char tail = 0;
        if (!arg.empty() && (std::sscanf(arg.c_str(), "%f%c", &ior, &tail) != 1 || !std::isfinite(ior)))
            throw UsageError(option, "glass:IOR expects a number, got '" + arg + "'");
        return glassMaterial(ior);
    }
    throw UsageError(option, "expected lambert[:r,g,b], mirror[:r,g,b] or glass[:ior], got '" + text + "'");
}

void applyClip(const std::string& axis, float lo, float hi, VolumeSettings& s, const std::string& option) {
    if ((axis != "x" && axis != "y" && axis != "z") || !(lo >= 0 && hi <= 1 && lo < hi))
        throw UsageError(option, "expected axis:lo:hi with axis x|y|z and 0 <= lo < hi <= 1, got '" + axis + ":" +
                                     std::to_string(lo) + ":" + std::to_string(hi) + "'");
    s.clipLo[axis[0] - 'x'] = lo;
    s.clipHi[axis[0] - 'x'] = hi;
}

void applyClipText(const std::string& text, VolumeSettings& s, const std::string& option) {
    char axis = 0, tail = 0;
    float lo = 0, hi = 0;
    if (std::sscanf(text.c_str(), "%c:%f:%f%c", &axis, &lo, &hi, &tail) != 3 ||
        (axis != 'x' && axis != 'y' && axis != 'z') || !(lo >= 0 && hi <= 1 && lo < hi))
        throw UsageError(option, "expected axis:lo:hi with axis x|y|z and 0 <= lo < hi <= 1, got '" + text + "'");
    applyClip(std::string(1, axis), lo, hi, s, option);
}

}  // namespace rtfact::engine
