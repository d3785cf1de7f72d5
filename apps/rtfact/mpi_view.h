// `mpirun -np N rtfact view ...` (docs/mpi.md): every rank loads the scene; rank 0 serves
// the viewer, and every pass of every tab is rendered by all ranks, image-parallel: rank 0
// sends the pass (tab, camera, settings, size, scale) to the others, each rank renders the
// tiles t = rank + k N of it into its own accumulation for that tab, and rank 0 gathers
// the resolved tiles (and the depth for eye-dome lighting) into the frame it streams.
// When rank 0's server stops, it tells the other ranks, which exit cleanly.
#pragma once
#include <functional>

#include "apps/view/client_session.h"
#include "engine/scene.h"

namespace rtfact::app {

struct ViewJob {
    engine::Scene scene;
    viewer::ViewerConfig config;
    bool quiet = false;  // rank 0 does not say how many ranks serve
};

// `prepare(root)`: options, settings and scene on every rank (only rank 0 prints);
// `serve`: rank 0's server, until it stops. Returns this rank's exit status.
int runMpiView(const std::function<ViewJob(bool root)>& prepare, const std::function<void(ViewJob&)>& serve);

}  // namespace rtfact::app
