// The options of `rtfact points` that choose how a cloud is prepared and shaded, shared
// by every command that renders point clouds (points, view).
#pragma once
#include <CLI/CLI.hpp>
#include <string>

#include "engine/settings.h"

namespace rtfact::app {

struct PointOptions {
    engine::PointSettings settings;
    std::string lod = "on";
    std::string color = "rgb";

    void addTo(CLI::App& cmd);
    // The settings the parsed options give.
    engine::Settings toSettings() const;
};

}  // namespace rtfact::app
