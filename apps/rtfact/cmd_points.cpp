// `rtfact points FILE`: load, prepare (normals, radii), build the LoD kd-tree, render.
// `rtfact gen points --from MESH --count N -o OUT.ply`: sample a mesh into a cloud.
// `rtfact info FILE` for point clouds (PLY without faces, PCD, XYZ/PTS).
#include <chrono>
#include <cstdio>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/render_command.h"
#include "core/render/ao_integrator.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "core/util/error.h"
#include "points/point_cloud_io.h"
#include "points/point_generator.h"
#include "points/point_scene.h"

namespace rtfact::app {

using namespace rtfact::points;

void addPointsCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        std::string file;
        float radius = 0.0f;
        float radiusFactor = 1.0f;
        std::string normals = "auto";
        float lodQuality = 2.0f;
        std::string lod = "on";
        std::string color = "rgb";
        std::string integrator = "eyelight";
        int aoSamples = 8;
        int leafSize = 8;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd =
        app.add_subcommand("points", "Render a point cloud (PLY, PCD, XYZ/PTS) as discs with a LoD kd-tree");
    // Sub-pixel splats make wide packets incoherent: 16 rays measured best (bench/bench_points.cpp).
    o->common.packet = 16;
    o->common.addTo(*cmd, "points.png");
    cmd->add_option("FILE", o->file, "Point cloud file (.ply .pcd .xyz .pts)")->required();
    auto* r =
        cmd->add_option("--radius", o->radius, "Disc radius for every point (world units)")->check(positiveFinite());
    cmd->add_option("--radius-factor", o->radiusFactor, "Scale of the radii (file radii or neighbour spacing)")
        ->capture_default_str()
        ->check(finiteRange(1e-3, 1e3))
        ->excludes(r);
    cmd->add_option("--normals", o->normals, "auto|estimate|file")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "estimate", "file"}));
    cmd->add_option("--lod-quality", o->lodQuality,
                    "Node answered by its representative disc when its size < footprint x Q (0: full detail)")
        ->capture_default_str()
        ->check(finiteRange(0.0, 64.0));
    cmd->add_option("--lod", o->lod, "on|off (off = full detail)")
        ->capture_default_str()
        ->check(CLI::IsMember({"on", "off"}));
    cmd->add_option("--color", o->color, "rgb|intensity|lod|normal")
        ->capture_default_str()
        ->check(CLI::IsMember({"rgb", "intensity", "lod", "normal"}));
    cmd->add_option("--integrator", o->integrator, "eyelight|direct|ao")
        ->capture_default_str()
        ->check(CLI::IsMember({"eyelight", "direct", "ao"}));
    cmd->add_option("--ao-samples", o->aoSamples, "AO rays per sample")
        ->capture_default_str()
        ->check(CLI::Range(1, 256));
    cmd->add_option("--leaf-size", o->leafSize, "Maximum points per kd-tree leaf")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    list.push_back(
        {cmd, [o] {
             CommonOptions& c = o->common;
             c.finalize();
             checkImageWritable(c.out);
             Stats stats;
             auto t0 = std::chrono::steady_clock::now();
             PointCloud cloud = loadPointCloud(o->file);
             const double loadMs = msSince(t0);
             stats.add("load_ms", loadMs);
             stats.add("points", (unsigned long long)cloud.size());
             stats.add("load_points_per_s", loadMs > 0 ? double(cloud.size()) / (loadMs * 1e-3) : 0.0);
             stats.add("dropped_nonfinite", (unsigned long long)cloud.droppedNonFinite);
             // Points lost on load are worth one line (all lost is an error in the loader).
             if (const std::string w = droppedPointsMessage(o->file, cloud); !w.empty() && !c.quiet)
                 std::fprintf(stderr, "rtfact: warning: %s\n", w.c_str());
             const CameraFrame frame = c.frame(cloud.bounds());
             PrepareOptions po;
             po.normals = o->normals;
             po.radius = o->radius;
             po.radiusFactor = o->radiusFactor;
             po.viewpoint = frame.eye;
             po.threads = c.threads;
             t0 = std::chrono::steady_clock::now();
             const PrepareReport pr = preparePointCloud(cloud, po, o->file);
             stats.add("prepare_ms", msSince(t0));
             stats.add("normals", pr.estimatedNormals ? "estimated" : "file");
             stats.add("radii", o->radius > 0 ? "fixed" : pr.estimatedRadii ? "spacing" : "file");
             const ColorMode mode = parseColorMode(o->color);
             t0 = std::chrono::steady_clock::now();
             PointScene scene;
             scene.colorMode = mode;
             {
                 std::vector<Disc> discs = makeDiscs(cloud, mode);
                 cloud = PointCloud{};  // the discs hold everything rendering needs
                 LoDKdTreeBuilder b;
                 b.maxLeafSize = o->leafSize;
                 scene.build(std::move(discs), b);
             }
             const double buildMs = msSince(t0);
             stats.add("build_ms", buildMs);
             stats.add("build_points_per_s", buildMs > 0 ? double(scene.tree.elems.size()) / (buildMs * 1e-3) : 0.0);
             stats.add("bytes_per_point", scene.tree.bytesPerPoint());
             stats.add("tree_nodes", (unsigned long long)scene.tree.nodes.size());
             const PinholeCamera cam(frame, c.width, c.height);
             scene.setLoD(cam.cone(), o->lod == "off" ? 0.0f : o->lodQuality);
             RenderStats rendered;
             if (o->integrator == "eyelight") {
                 rendered = renderToFile(scene, EyeLightIntegrator{}, c, frame, stats);
             } else if (o->integrator == "ao") {
                 AOIntegrator ao;
                 ao.samples = o->aoSamples;
                 // Splats overlap their neighbours: start AO rays clear of the local surface.
                 ao.offset = 4e-3f;
                 ao.minDistance = 4e-3f;
                 rendered = renderToFile(scene, ao, c, frame, stats);
             } else {
                 DirectLightIntegrator integ;
                 const AABB b = scene.bounds();
                 const Vec3f e = b.extent();
                 const Vec3f toEye = normalize(frame.eye - frame.at);
                 integ.lights.push_back(PointLight{frame.eye + Vec3f(0, 1, 0) * length(e) + toEye * 0.2f * length(e),
                                                   Vec3f(2.5f * dot(e, e))});
                 integ.lights.push_back(DirectionalLight{{0.3f, -1.0f, -0.4f}, Vec3f(0.5f)});
                 rendered = renderToFile(scene, integ, c, frame, stats);
             }
             stats.add("lod_nodes_hit", (unsigned long long)rendered.counters.lodNodesHit);
             stats.add("lod_quality", o->lod == "off" ? 0.0 : double(o->lodQuality));
             if (c.stats) stats.print();
             return 0;
         }});
}

void addGenPointsCommand(CLI::App& gen, CommandList& list) {
    struct Opts {
        std::string from, out;
        unsigned long long count = 1000000;
        unsigned long long seed = 1;
        float radiusFactor = 2.2f;
        bool quiet = false;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd =
        gen.add_subcommand("points", "Sample a triangle mesh (PLY) into a point cloud PLY with normals and radii");
    cmd->add_option("--from", o->from, "Input mesh (.ply with faces)")->required();
    cmd->add_option("--count", o->count, "Number of points")
        ->capture_default_str()
        ->check(CLI::Range(1ull, 500000000ull));
    cmd->add_option("-o,--out", o->out, "Output .ply")->required();
    cmd->add_option("--seed", o->seed, "Random seed")->capture_default_str();
    cmd->add_option("--radius-factor", o->radiusFactor, "Disc radius in units of sqrt(area / (count pi))")
        ->capture_default_str()
        ->check(finiteRange(0.1, 100.0));
    cmd->add_flag("--quiet", o->quiet, "No messages");
    list.push_back({cmd, [o] {
                        const auto t0 = std::chrono::steady_clock::now();
                        const TriangleMesh mesh = loadPlyMesh(o->from);
                        PointCloud pc = samplePointsOnMesh(mesh, size_t(o->count), o->seed, o->radiusFactor);
                        writePly(o->out, pc);
                        if (!o->quiet)
                            std::printf("wrote %s: %zu points from %zu triangles in %.0f ms\n", o->out.c_str(),
                                        pc.size(), mesh.triangles.size(), msSince(t0));
                        return 0;
                    }});
}

std::optional<int> pointsInfo(const std::string& file) {
    const auto info = probePointFile(file);
    if (!info) return std::nullopt;
    std::printf("file: %s\ntype: point cloud\nformat: %s\npoints: %zu\nproperties:", file.c_str(), info->format.c_str(),
                info->points);
    for (const auto& p : info->properties) std::printf(" %s", p.c_str());
    std::printf("\n");
    return 0;
}

}  // namespace rtfact::app
