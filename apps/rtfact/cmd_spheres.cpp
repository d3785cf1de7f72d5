// `rtfact spheres`: the analytic demo scene of the core.
#include <chrono>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/render_command.h"
#include "core/geometry/sphere_scene.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"

namespace rtfact::app {

void addSpheresCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        int count = 400;
        std::string integrator = "direct";
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd = app.add_subcommand("spheres", "Render the analytic sphere demo scene");
    o->common.addTo(*cmd, "spheres.png");
    cmd->add_option("--count", o->count, "Number of small spheres")
        ->capture_default_str()
        ->check(CLI::Range(0, 10000000));
    cmd->add_option("--integrator", o->integrator, "eyelight|direct")
        ->capture_default_str()
        ->check(CLI::IsMember({"eyelight", "direct"}));
    list.push_back({cmd, [o] {
                        CommonOptions& c = o->common;
                        c.finalize();
                        checkImageWritable(c.out);
                        Stats stats;
                        const auto t0 = std::chrono::steady_clock::now();
                        SphereScene scene = SphereScene::demo(o->count);
                        stats.add("load_ms", 0.0);
                        stats.add("build_ms", msSince(t0));
                        stats.add("primitives", (unsigned long long)scene.spheres.size());
                        // Fit the view to the small spheres, not the ground sphere.
                        AABB focus;
                        for (size_t i = 1; i < scene.spheres.size(); ++i) focus.extend(scene.spheres[i].bounds());
                        if (focus.isEmpty()) focus = AABB{{-1, 0, -1}, {1, 1, 1}};
                        const CameraFrame frame = c.frame(focus, {0.0f, 0.8f, 1.0f});
                        if (o->integrator == "eyelight") {
                            renderToFile(scene, EyeLightIntegrator{}, c, frame, stats);
                        } else {
                            DirectLightIntegrator integ;
                            const Vec3f e = focus.extent();
                            integ.lights.push_back(
                                PointLight{focus.center() + Vec3f(-0.6f * e.x, 2.0f * e.y + 0.5f * e.x, 0.4f * e.z),
                                           Vec3f(1.2f * dot(e, e))});
                            integ.lights.push_back(DirectionalLight{{0.3f, -1.0f, -0.4f}, Vec3f(0.6f)});
                            renderToFile(scene, integ, c, frame, stats);
                        }
                        if (c.stats) stats.print();
                        return 0;
                    }});
}

}  // namespace rtfact::app
