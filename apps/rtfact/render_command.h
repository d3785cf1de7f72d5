// The one skeleton of every rendering subcommand: finalize the common options, turn the
// command's options into engine settings, check the output, open the scene through the
// engine, fit the camera, render, write the image, print the stats.
#pragma once
#include <functional>

#include "apps/rtfact/common_options.h"
#include "engine/scene.h"
#include "engine/settings.h"

namespace rtfact::app {

// `settings` runs before any input is read (option errors first); `open` loads the scene.
int runRenderCommand(CommonOptions& c, const std::function<engine::Settings()>& settings,
                     const std::function<engine::Scene()>& open);

}  // namespace rtfact::app
