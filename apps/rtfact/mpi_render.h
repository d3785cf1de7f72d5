// Cooperative rendering under mpirun (docs/mpi.md). Image-parallel: every rank loads the
// scene, rank 0 hands out tiles one at a time to whichever rank asks (so an uneven image
// balances), every rank renders its tiles through the engine, rank 0 gathers them and
// writes the image, bit-identical to the single-process render (same tiles, same samples,
// same per-pixel seeds). A rank's failure ends every rank with one error line naming it.
#pragma once
#include <functional>

#include "apps/rtfact/common_options.h"
#include "apps/rtfact/render_command.h"
#include "engine/scene.h"
#include "engine/settings.h"

namespace rtfact::app {

// True when this process was started by mpirun with more than one process (with one,
// or without mpirun, rtfact renders alone and MPI is never initialised).
bool mpiLaunched();

// runRenderCommand's MPI counterpart; returns the exit status of this rank. `data`: the
// command can also render data-parallel (--distribute data).
int runMpiRender(CommonOptions& c, const std::function<engine::Settings()>& settings,
                 const std::function<engine::Scene()>& open, const DataSource* data = nullptr);

}  // namespace rtfact::app
