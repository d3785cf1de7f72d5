#include "apps/rtfact/render_command.h"

#include <cstdio>

#include "core/render/image_io.h"
#include "engine/render_session.h"

namespace rtfact::app {

int runRenderCommand(CommonOptions& c, const std::function<engine::Settings()>& settings,
                     const std::function<engine::Scene()>& open) {
    c.finalize();
    const engine::Settings s = settings();
    checkImageWritable(c.out);
    const engine::Scene scene = open();
    if (!c.quiet)
        for (const std::string& w : scene.warnings()) std::fprintf(stderr, "rtfact: warning: %s\n", w.c_str());
    engine::Stats stats = scene.loadStats();
    const engine::DefaultView view = scene.defaultView(s);
    const CameraFrame frame = c.frame(view.focus, view.viewDir, view.up);
    engine::FrameOptions fo;
    fo.width = c.width;
    fo.height = c.height;
    fo.packet = c.packet;
    fo.threads = c.threads;
    fo.progress = !c.quiet;
    fo.target = c.out;
    const engine::Frame image = engine::renderToImage(scene, s, fo, frame, c.spp, stats);
    writeImage(c.out, image.width, image.height, image.rgba);
    if (c.stats) stats.print();
    return 0;
}

}  // namespace rtfact::app
