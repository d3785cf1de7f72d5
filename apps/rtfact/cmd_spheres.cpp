// `rtfact spheres`: the analytic demo scene of the core.
#include "apps/rtfact/commands.h"
#include "apps/rtfact/render_command.h"

namespace rtfact::app {

void addSpheresCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        int count = 400;
        engine::SpheresSettings settings;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd = app.add_subcommand("spheres", "Render the analytic sphere demo scene");
    o->common.addTo(*cmd, "spheres.png");
    cmd->add_option("--count", o->count, "Number of small spheres")
        ->capture_default_str()
        ->check(CLI::Range(0, 10000000));
    cmd->add_option("--integrator", o->settings.integrator, joined(engine::spheresIntegrators()))
        ->capture_default_str()
        ->check(CLI::IsMember(engine::spheresIntegrators()));
    list.push_back({cmd, [o] {
                        return runRenderCommand(
                            o->common,
                            [&] {
                                engine::Settings s;
                                s.spheres = o->settings;
                                return s;
                            },
                            [&] { return engine::spheres(o->count); });
                    }});
}

}  // namespace rtfact::app
