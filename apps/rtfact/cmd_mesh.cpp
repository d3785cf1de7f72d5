// `rtfact mesh FILE...`: triangle meshes on the core's BVH or kd-tree, rendered with the
// core's eyelight/direct-light integrators or the surface library's AO integrator and
// path tracer.
// `rtfact info` for mesh files.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/render_command.h"
#include "core/render/ao_integrator.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "core/util/error.h"
#include "surfaces/mesh_loader.h"
#include "surfaces/mesh_scene.h"
#include "surfaces/path_integrator.h"
#include "surfaces/whitted_integrator.h"

namespace rtfact::app {

namespace {

struct MeshOpts {
    CommonOptions common;
    std::vector<std::string> files;
    std::string integrator = "direct";
    std::vector<std::string> lights;
    std::string material;
    std::string bvh = "sah";
    int aoSamples = 16;
    std::string secondary = "auto";  // traversal of AO / bounce rays: auto | wide | packet
    int maxDepth = 6;
};

// Lights are scaled so that the scene centre receives an irradiance of 0.85 (white
// surfaces facing the light stay below clipping).
PointLight scaledPointLight(Vec3f p, const AABB& box) {
    const Vec3f d = p - box.center();
    return PointLight{p, Vec3f(0.85f * 3.14159265f * std::max(dot(d, d), 1e-12f))};
}

// "point:x,y,z" or "dir:x,y,z".
AnyLight parseLight(const std::string& s, const AABB& box) {
    const size_t c = s.find(':');
    const std::string kind = c == std::string::npos ? "" : s.substr(0, c);
    if (kind == "point") return scaledPointLight(parseVec3(s.substr(c + 1), "--light"), box);
    if (kind == "dir") {
        const Vec3f d = parseVec3(s.substr(c + 1), "--light");
        if (length(d) == 0.0f) throw CLI::ValidationError("--light", "direction must not be zero");
        return DirectionalLight{normalize(d), Vec3f(0.85f * 3.14159265f)};
    }
    throw CLI::ValidationError("--light", "expected point:x,y,z or dir:x,y,z, got '" + s + "'");
}

// --material lambert[:r,g,b] | mirror[:r,g,b] | glass[:ior] replaces every material.
void applyMaterial(Mesh& m, const std::string& spec) {
    if (spec.empty()) return;
    const size_t c = spec.find(':');
    const std::string kind = spec.substr(0, c), arg = c == std::string::npos ? "" : spec.substr(c + 1);
    MeshMaterial mat;
    mat.name = kind;
    if (kind == "lambert") {
        if (!arg.empty()) mat.kd = parseVec3(arg, "--material");
    } else if (kind == "mirror") {
        mat.illum = 3;
        mat.kd = Vec3f(0.0f);
        mat.ks = arg.empty() ? Vec3f(0.95f) : parseVec3(arg, "--material");
    } else if (kind == "glass") {
        mat.illum = 7;
        mat.dissolve = 0.0f;
        mat.kd = Vec3f(1.0f);
        try {
            size_t used = 0;
            mat.ior = arg.empty() ? 1.5f : std::stof(arg, &used);
            if (!arg.empty() && used != arg.size()) throw std::invalid_argument(arg);
        } catch (const std::exception&) {
            throw CLI::ValidationError("--material", "glass:IOR expects a number, got '" + arg + "'");
        }
        if (!(mat.ior >= 1.0f && mat.ior <= 4.0f))
            throw CLI::ValidationError("--material", "glass IOR must be in [1, 4]");
    } else {
        throw CLI::ValidationError("--material",
                                   "expected lambert[:r,g,b], mirror[:r,g,b] or glass[:ior], got '" + spec + "'");
    }
    m.materials = {mat};
    m.materialIds.assign(m.triangles(), 0);
    m.colors.clear();
}

template <class Secondary, class Scene>
void renderSecondary(const MeshOpts& o, const Scene& scene, const Mesh& mesh, const CameraFrame& frame, Stats& stats) {
    const CommonOptions& c = o.common;
    if (o.integrator == "path") {
        PathIntegratorT<Secondary> pt;
        pt.maxDepth = o.maxDepth;
        pt.materials = PathIntegrator::fromMesh(mesh);
        // Without emitters (MTL Ke) the scene is lit by a bright sky.
        const bool emitters = std::any_of(pt.materials.begin(), pt.materials.end(),
                                          [](const PathMaterial& m) { return maxComponent(m.emission) > 0.0f; });
        if (!emitters) pt.background = Vec3f(0.9f, 0.95f, 1.0f);
        renderToFile(scene, pt, c, frame, stats);
    } else {
        AOIntegratorT<Secondary> ao;
        ao.samples = o.aoSamples;
        renderToFile(scene, ao, c, frame, stats);
    }
}

template <class Structure>
int renderMesh(const MeshOpts& o, std::shared_ptr<const Mesh> mesh, Stats& stats) {
    const CommonOptions& c = o.common;
    const auto t0 = std::chrono::steady_clock::now();
    // Only integrators with incoherent rays need the wide BVH.
    const bool incoherent = o.integrator == "path" || o.integrator == "ao";
    // auto: the integrator's own default (AO: packets, path bounces: wide single rays).
    const std::string secondary = o.secondary != "auto" ? o.secondary : o.integrator == "path" ? "wide" : "packet";
    MeshScene<Structure> scene;
    scene.mesh = mesh;
    scene.buildWide = incoherent && secondary == "wide";
    scene.build();
    stats.add("build_ms", msSince(t0));
    stats.add("triangles", (unsigned long long)mesh->triangles());
    stats.add("bvh_bytes", (unsigned long long)scene.memoryBytes());
    const AABB box = scene.bounds();
    const CameraFrame frame = c.frame(box);
    if (o.integrator == "eyelight") {
        renderToFile(scene, EyeLightIntegrator{}, c, frame, stats);
    } else if (incoherent) {
        stats.add("secondary", secondary);
        if (secondary == "wide")
            renderSecondary<WideSecondaryRays>(o, scene, *mesh, frame, stats);
        else
            renderSecondary<PacketSecondaryRays>(o, scene, *mesh, frame, stats);
    } else {
        LightList lights;
        for (const std::string& l : o.lights) lights.push_back(parseLight(l, box));
        if (lights.empty()) {
            // Default: a key light above and to the left of the camera. Built directly: a
            // round trip through "point:x,y,z" text lost small coordinates (6 decimals) and
            // blamed --light for any non-finite camera.
            const Vec3f e = box.extent();
            const float r = std::max(length(e), 1e-6f);
            const Vec3f p = frame.eye + normalize(frame.up) * (0.8f * r) -
                            normalize(cross(frame.at - frame.eye, frame.up)) * (0.6f * r);
            lights.push_back(scaledPointLight(p, box));
        }
        if (o.integrator == "whitted") {
            WhittedIntegrator w;
            w.lights = lights;
            w.maxDepth = o.maxDepth;
            w.materials = PathIntegrator::fromMesh(*mesh);
            renderToFile(scene, w, c, frame, stats);
        } else {
            DirectLightIntegrator integ;
            integ.lights = lights;
            renderToFile(scene, integ, c, frame, stats);
        }
    }
    return 0;
}

}  // namespace

void addMeshCommand(CLI::App& app, CommandList& list) {
    auto o = std::make_shared<MeshOpts>();
    CLI::App* cmd = app.add_subcommand("mesh", "Render triangle meshes (PLY, OBJ+MTL, STL, VTK, VTP)");
    o->common.addTo(*cmd, "mesh.png");
    cmd->add_option("FILE", o->files, "Mesh files (several are merged into one scene)")->required();
    cmd->add_option("--integrator", o->integrator, "eyelight|direct|whitted|ao|path (path: progressive, use --spp)")
        ->capture_default_str()
        ->check(CLI::IsMember({"eyelight", "direct", "whitted", "ao", "path"}));
    cmd->add_option("--max-depth", o->maxDepth, "Whitted/path tracer: maximum ray depth")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd->add_option("--light", o->lights, "Light point:x,y,z or dir:x,y,z (repeatable; default: a key light)");
    cmd->add_option(
        "--material", o->material,
        "Override all materials: lambert[:r,g,b] | mirror[:r,g,b] | glass[:ior] (mirror/glass: whitted, path)");
    cmd->add_option("--bvh", o->bvh, "Acceleration structure: sah (binned SAH BVH) | kdtree (SAH kd-tree)")
        ->capture_default_str()
        ->check(CLI::IsMember({"sah", "kdtree"}));
    cmd->add_option("--ao-samples", o->aoSamples, "Ambient occlusion rays per hit")
        ->capture_default_str()
        ->check(CLI::Range(1, 1024));
    cmd->add_option("--secondary", o->secondary,
                    "AO / path bounce rays: wide (single rays through a wide BVH), packet (the packet BVH) or auto "
                    "(AO: packet, path: wide)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "wide", "packet"}));
    list.push_back({cmd, [o] {
                        CommonOptions& c = o->common;
                        c.finalize();
                        for (const std::string& l : o->lights) parseLight(l, AABB{{0, 0, 0}, {1, 1, 1}});
                        checkImageWritable(c.out);
                        Stats stats;
                        const auto t0 = std::chrono::steady_clock::now();
                        auto mesh = std::make_shared<Mesh>(loadMeshes(o->files));
                        applyMaterial(*mesh, o->material);
                        stats.add("load_ms", msSince(t0));
                        if (o->bvh == "kdtree")
                            renderMesh<KdTree<Triangle>>(*o, mesh, stats);
                        else
                            renderMesh<BVH<Triangle>>(*o, mesh, stats);
                        if (c.stats) stats.print();
                        return 0;
                    }});
}

std::optional<int> meshInfo(const std::string& file) {
    const MeshFileKind kind = meshFileKind(file);
    if (kind == MeshFileKind::NotMesh) return std::nullopt;
    const char* names[] = {"", "PLY", "OBJ", "STL", "VTK legacy", "VTP"};
    const Mesh m = loadMesh(file);
    const AABB b = m.bounds();
    std::printf("file: %s\n", file.c_str());
    std::printf("type: mesh (%s)\n", names[int(kind)]);
    std::printf("vertices: %zu\n", m.positions.size());
    std::printf("triangles: %zu\n", m.triangles());
    std::printf("bounds: [%g, %g, %g] - [%g, %g, %g]\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
    std::printf("normals: %s\n", m.normalsComputed ? "computed (none in file)" : "from file");
    std::printf("uvs: %s\n", m.uvs.empty() ? "no" : "yes");
    std::printf("colors: %s\n", m.colors.empty() ? "no" : "yes");
    std::printf("materials: %zu\n", m.materials.size());
    for (const MeshMaterial& mm : m.materials)
        std::printf("  %s: kd=%g,%g,%g%s%s\n", mm.name.c_str(), mm.kd.x, mm.kd.y, mm.kd.z,
                    mm.diffuseMap.empty() ? "" : " map_Kd=", mm.diffuseMap.c_str());
    return 0;
}

}  // namespace rtfact::app
