// `rtfact mesh FILE...`: triangle meshes on the BVH or kd-tree, rendered through the
// engine with the eyelight, direct-light, Whitted, AO or path-tracing integrator.
#include <stdexcept>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/render_command.h"

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

void addMeshCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        std::vector<std::string> files;
        engine::MeshSettings settings;
        std::vector<std::string> lights;
        std::string material;
    };
    auto o = std::make_shared<Opts>();
    engine::MeshSettings& ms = o->settings;
    CLI::App* cmd = app.add_subcommand("mesh", "Render triangle meshes (PLY, OBJ+MTL, STL, VTK, VTP)");
    o->common.addTo(*cmd, "mesh.png");
    cmd->add_option("FILE", o->files, "Mesh files (several are merged into one scene)")->required();
    cmd->add_option("--integrator", ms.integrator,
                    joined(engine::meshIntegrators()) + " (path: progressive, use --spp)")
        ->capture_default_str()
        ->check(CLI::IsMember(engine::meshIntegrators()));
    cmd->add_option("--max-depth", ms.maxDepth, "Whitted/path tracer: maximum ray depth")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd->add_option("--light", o->lights, "Light point:x,y,z or dir:x,y,z (repeatable; default: a key light)");
    cmd->add_option(
        "--material", o->material,
        "Override all materials: lambert[:r,g,b] | mirror[:r,g,b] | glass[:ior] (mirror/glass: whitted, path)");
    cmd->add_option("--bvh", ms.bvh, "Acceleration structure: sah (binned SAH BVH) | kdtree (SAH kd-tree)")
        ->capture_default_str()
        ->check(CLI::IsMember({"sah", "kdtree"}));
    cmd->add_option("--ao-samples", ms.aoSamples, "Ambient occlusion rays per hit")
        ->capture_default_str()
        ->check(CLI::Range(1, 1024));
    cmd->add_option("--secondary", ms.secondary,
                    "AO / path bounce rays: wide (single rays through a wide BVH), packet (the packet BVH) or auto "
                    "(AO: packet, path: wide)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "wide", "packet"}));
    list.push_back({cmd, [o] {
                        return runRenderCommand(
                            o->common,
                            [&] {
                                engine::Settings s;
                                s.mesh = o->settings;
                                for (const std::string& l : o->lights) s.mesh.lights.push_back(parseLight(l));
                                if (!o->material.empty()) s.mesh.material = parseMaterial(o->material);
                                return s;
                            },
                            [&] {
                                engine::OpenOptions oo;
                                oo.kind = engine::SceneKind::Mesh;
                                oo.progress = !o->common.quiet;
                                oo.keepSource = false;
                                return engine::open(o->files, oo);
                            });
                    }});
}

}  // namespace rtfact::app
