// The options of `rtfact mesh` (integrator, lights, material, BVH ...), shared by every
// command that renders meshes (mesh, view).
#pragma once
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "engine/settings.h"

namespace rtfact::app {

struct MeshOptions {
    engine::MeshSettings settings;
    std::vector<std::string> lights;
    std::string material;

    void addTo(CLI::App& cmd);
    // The settings the parsed options give; throws CLI::ValidationError on a bad --light
    // or --material.
    engine::Settings toSettings() const;
};

}  // namespace rtfact::app
