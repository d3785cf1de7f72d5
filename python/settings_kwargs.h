// Keyword arguments -> engine settings, named like the CLI's options with underscores
// (`rtfact points --radius-factor 2` is `radius_factor=2`). The names a scene kind
// accepts are those of its CLI subcommand plus the shared ones; an unknown name is a
// TypeError, a bad value a ValueError naming the argument, checked with the CLI's ranges.
#pragma once
#include <pybind11/pybind11.h>

#include <optional>

#include "core/render/pinhole_camera.h"
#include "engine/render_session.h"
#include "engine/scene.h"
#include "engine/settings.h"

namespace rtfact::python {

struct RenderRequest {
    engine::Settings settings;
    engine::FrameOptions frame;  // size, threads, packet, progress (off unless asked)
    int spp = 1;
    std::optional<Vec3f> eye, at, up;
    float fov = 45.0f;
};

// The settings of a render of a `kind` scene from `kwargs`.
RenderRequest renderRequest(engine::SceneKind kind, const pybind11::dict& kwargs);

// `camera` when given (eye/at/up/fov arguments are then refused), else the scene's
// default view fitted for the request's aspect, with eye/at/up/fov applied as the CLI does.
CameraFrame requestCamera(const engine::Scene& scene, const RenderRequest& r, const std::optional<CameraFrame>& camera,
                          bool cameraArgs);

// load() options: kind, dims, type, endian, spacing, header_skip, grid, progress.
engine::OpenOptions openOptions(const pybind11::dict& kwargs);

// A transfer function from a preset name, a .json file (ours or a ParaView preset), a
// dict in either JSON form, or a list of (x, r, g, b, a) rows (x in 0..1 over the window,
// sRGB colour and opacity in 0..1).
volume::TransferFunction transferFunctionFrom(pybind11::handle tf);

// Parses a camera vector argument: a sequence of 3 finite numbers or "x,y,z".
Vec3f vec3Arg(pybind11::handle h, const std::string& name);

}  // namespace rtfact::python
