#include "apps/rtfact/mesh_options.h"

#include <stdexcept>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/common_options.h"

namespace rtfact::app {

namespace {

// "point:x,y,z" or "dir:x,y,z".
engine::LightSpec parseLight(const std::string& s) {
    const size_t c = s.find(':');
    const std::string kind = c == std::string::npos ? "" : s.substr(0, c);
    if (kind == "point") return {engine::LightSpec::Kind::Point, parseVec3(s.substr(c + 1), "--light")};
    if (kind == "dir") return {engine::LightSpec::Kind::Directional, parseVec3(s.substr(c + 1), "--light")};
    throw CLI::ValidationError("--light", "expected point:x,y,z or dir:x,y,z, got '" + s + "'");
}

// --material lambert[:r,g,b] | mirror[:r,g,b] | glass[:ior] replaces every material.
MeshMaterial parseMaterial(const std::string& spec) {
    const size_t c = spec.find(':');
    const std::string kind = spec.substr(0, c), arg = c == std::string::npos ? "" : spec.substr(c + 1);
    auto colour = [&]() -> std::optional<Vec3f> {
        if (arg.empty()) return std::nullopt;
        return parseVec3(arg, "--material");
    };
    if (kind == "lambert") return engine::lambertMaterial(colour());
    if (kind == "mirror") return engine::mirrorMaterial(colour());
    if (kind == "glass") {
        float ior = 1.5f;
        try {
            size_t used = 0;
            if (!arg.empty()) ior = std::stof(arg, &used);
            if (!arg.empty() && used != arg.size()) throw std::invalid_argument(arg);
        } catch (const std::exception&) {
            throw CLI::ValidationError("--material", "glass:IOR expects a number, got '" + arg + "'");
        }
        return engine::glassMaterial(ior);
    }
    throw CLI::ValidationError("--material",
                               "expected lambert[:r,g,b], mirror[:r,g,b] or glass[:ior], got '" + spec + "'");
}

}  // namespace

void MeshOptions::addTo(CLI::App& cmd) {
    cmd.add_option("--integrator", settings.integrator,
                   joined(engine::meshIntegrators()) + " (path: progressive, use --spp)")
        ->capture_default_str()
        ->check(CLI::IsMember(engine::meshIntegrators()));
    cmd.add_option("--max-depth", settings.maxDepth, "Whitted/path tracer: maximum ray depth")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd.add_option("--light", lights, "Light point:x,y,z or dir:x,y,z (repeatable; default: a key light)");
    cmd.add_option(
        "--material", material,
        "Override all materials: lambert[:r,g,b] | mirror[:r,g,b] | glass[:ior] (mirror/glass: whitted, path)");
    cmd.add_option("--bvh", settings.bvh, "Acceleration structure: sah (binned SAH BVH) | kdtree (SAH kd-tree)")
        ->capture_default_str()
        ->check(CLI::IsMember({"sah", "kdtree"}));
    cmd.add_option("--ao-samples", settings.aoSamples, "Ambient occlusion rays per hit")
        ->capture_default_str()
        ->check(CLI::Range(1, 1024));
    cmd.add_option("--secondary", settings.secondary,
                   "AO / path bounce rays: wide (single rays through a wide BVH), packet (the packet BVH) or auto "
                   "(AO: packet, path: wide)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "wide", "packet"}));
}

engine::Settings MeshOptions::toSettings() const {
    engine::Settings s;
    s.mesh = settings;
    for (const std::string& l : lights) s.mesh.lights.push_back(parseLight(l));
    if (!material.empty()) s.mesh.material = parseMaterial(material);
    return s;
}

}  // namespace rtfact::app
