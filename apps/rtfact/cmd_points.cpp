// `rtfact points FILE`: a point cloud rendered as discs through the engine.
// `rtfact gen points --from MESH --count N -o OUT.ply`: sample a mesh into a cloud.
#include <chrono>
#include <cstdio>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/point_options.h"
#include "apps/rtfact/render_command.h"
#include "engine/built_scene.h"
#include "engine/render_session.h"
#include "engine/stats.h"
#include "points/point_cloud_io.h"
#include "points/point_generator.h"

namespace rtfact::app {

using namespace rtfact::points;

void addPointsCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        std::string file;
        PointOptions points;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd =
        app.add_subcommand("points", "Render a point cloud (PLY, PCD, XYZ/PTS, LAS/LAZ) as discs with a LoD kd-tree");
    o->common.packet = engine::defaultPacketSize(engine::SceneKind::Points);
    o->common.addTo(*cmd, "points.png");
    cmd->add_option("FILE", o->file, "Point cloud file (.ply .pcd .xyz .pts .las .laz)")->required();
    o->points.addTo(*cmd);
    list.push_back({cmd, [o] {
                        auto options = [&] {
                            engine::OpenOptions oo;
                            oo.kind = engine::SceneKind::Points;
                            oo.progress = !o->common.quiet;
                            oo.keepSource = false;
                            oo.points = o->points.loadFilter();
                            return oo;
                        };
                        const DataSource data{engine::SceneKind::Points, o->file, options};
                        return runRenderCommand(
                            o->common, [&] { return o->points.toSettings(); },
                            [&] { return engine::open({o->file}, options()); }, &data);
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
        gen.add_subcommand("points", "Sample a triangle mesh into a point cloud PLY with normals and radii");
    cmd->add_option("--from", o->from, "Input mesh (.ply .obj .stl .vtk .vtp)")->required();
    cmd->add_option("--count", o->count, "Number of points")
        ->capture_default_str()
        ->check(CLI::Range(1ull, 500000000ull));
    cmd->add_option("-o,--out", o->out, "Output .ply")->required();
    cmd->add_option("--seed", o->seed, "Random seed")->capture_default_str();
    cmd->add_option("--radius-factor", o->radiusFactor, "Disc radius in units of sqrt(area / (count pi))")
        ->capture_default_str()
        ->check(finiteRange(0.1, 100.0));
    cmd->add_flag("--quiet", o->quiet, "No messages");
    list.push_back(
        {cmd, [o] {
             const auto t0 = std::chrono::steady_clock::now();
             // Any mesh the engine opens (PLY, OBJ, STL, VTK, VTP), through the one reader per format.
             engine::OpenOptions oo;
             oo.kind = engine::SceneKind::Mesh;
             oo.progress = !o->quiet;
             const auto loaded = engine::loadedMesh(engine::open({o->from}, oo));
             TriangleMesh mesh;
             mesh.vertices = loaded->positions;
             mesh.triangles.resize(loaded->triangles());
             for (size_t t = 0; t < mesh.triangles.size(); ++t)
                 mesh.triangles[t] = {loaded->indices[3 * t], loaded->indices[3 * t + 1], loaded->indices[3 * t + 2]};
             PointCloud pc = samplePointsOnMesh(mesh, size_t(o->count), o->seed, o->radiusFactor);
             writePly(o->out, pc);
             if (!o->quiet)
                 std::printf("wrote %s: %zu points from %zu triangles in %.0f ms\n", o->out.c_str(), pc.size(),
                             mesh.triangles.size(), engine::msSince(t0));
             return 0;
         }});
}

}  // namespace rtfact::app
