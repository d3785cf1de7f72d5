// The one skeleton of every rendering subcommand: finalize the common options, turn the
// command's options into engine settings, check the output, open the scene through the
// engine, fit the camera, render, write the image, print the stats.
#pragma once
#include <functional>
#include <string>

#include "apps/rtfact/common_options.h"
#include "engine/render_session.h"
#include "engine/scene.h"
#include "engine/settings.h"

namespace rtfact::app {

// What a command that can render data-parallel under mpirun (docs/mpi.md) reads: each
// rank then opens only its part of `file`.
struct DataSource {
    engine::SceneKind kind = engine::SceneKind::Volume;
    std::string file;
    std::function<engine::OpenOptions()> options;
};

// `settings` runs before any input is read (option errors first); `open` loads the scene.
int runRenderCommand(CommonOptions& c, const std::function<engine::Settings()>& settings,
                     const std::function<engine::Scene()>& open, const DataSource* data = nullptr);

// The skeleton up to the render: settings, scene (with its load statistics), camera and
// frame options. `writer`: this process writes the image (checks the output first, prints
// the scene's warnings); under MPI only rank 0 is.
struct RenderJob {
    engine::Settings settings;
    engine::Scene scene;
    engine::Stats stats;
    CameraFrame camera;
    engine::FrameOptions frame;
};
RenderJob prepareRender(CommonOptions& c, const std::function<engine::Settings()>& settings,
                        const std::function<engine::Scene()>& open, bool writer);

}  // namespace rtfact::app
