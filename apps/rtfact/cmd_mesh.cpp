// `rtfact mesh FILE...`: triangle meshes on the BVH or kd-tree, rendered through the
// engine with the eyelight, direct-light, Whitted, AO or path-tracing integrator.
#include "apps/rtfact/commands.h"
#include "apps/rtfact/mesh_options.h"
#include "apps/rtfact/render_command.h"

namespace rtfact::app {

void addMeshCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        std::vector<std::string> files;
        MeshOptions mesh;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd = app.add_subcommand("mesh", "Render triangle meshes (PLY, OBJ+MTL, STL, VTK, VTP)");
    o->common.addTo(*cmd, "mesh.png");
    cmd->add_option("FILE", o->files, "Mesh files (several are merged into one scene)")->required();
    o->mesh.addTo(*cmd);
    list.push_back({cmd, [o] {
                        return runRenderCommand(
                            o->common, [&] { return o->mesh.toSettings(); },
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
