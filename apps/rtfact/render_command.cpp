#include "apps/rtfact/render_command.h"

#include <cstdio>

#include "core/render/image_io.h"
#ifdef RTFACT_MPI
#include "apps/rtfact/mpi_render.h"
#endif

namespace rtfact::app {

RenderJob prepareRender(CommonOptions& c, const std::function<engine::Settings()>& settings,
                        const std::function<engine::Scene()>& open, bool writer) {
    c.finalize();
    RenderJob job;
    job.settings = settings();
    if (writer) checkImageWritable(c.out);
    job.scene = open();
    if (writer && !c.quiet)
        for (const std::string& w : job.scene.warnings()) std::fprintf(stderr, "rtfact: warning: %s\n", w.c_str());
    job.stats = job.scene.loadStats();
    const engine::DefaultView view = job.scene.defaultView(job.settings);
    job.camera = c.frame(view.focus, view.viewDir, view.up);
    job.frame.width = c.width;
    job.frame.height = c.height;
    job.frame.packet = c.packet;
    job.frame.threads = c.threads;
    job.frame.progress = !c.quiet;
    job.frame.target = c.out;
    return job;
}

int runRenderCommand(CommonOptions& c, const std::function<engine::Settings()>& settings,
                     const std::function<engine::Scene()>& open, const DataSource* data) {
#ifdef RTFACT_MPI
    if (mpiLaunched()) return runMpiRender(c, settings, open, data);
#else
    (void)data;
#endif
    RenderJob job = prepareRender(c, settings, open, true);
    const engine::Frame image = engine::renderToImage(job.scene, job.settings, job.frame, job.camera, c.spp, job.stats);
    writeImage(c.out, image.width, image.height, image.rgba);
    if (c.stats) job.stats.print();
    return 0;
}

}  // namespace rtfact::app
