#include "apps/rtfact/mesh_options.h"

#include "apps/rtfact/commands.h"
#include "apps/rtfact/common_options.h"
#include "engine/setting_text.h"

namespace rtfact::app {

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
                   "AO / path bounce rays: wide (single rays through the wide BVH, whose packets trace every "
                   "coherent ray), packet (every ray through a binary packet BVH instead) or auto (wide)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "wide", "packet"}));
}

engine::Settings MeshOptions::toSettings() const {
    engine::Settings s;
    s.mesh = settings;
    for (const std::string& l : lights) s.mesh.lights.push_back(engine::parseLightText(l, "--light"));
    if (!material.empty()) s.mesh.material = engine::parseMaterialText(material, "--material");
    return s;
}

}  // namespace rtfact::app
