// The options of `rtfact points` that choose how a cloud is loaded, prepared, coloured
// and shaded, shared by every command that renders point clouds (points, view).
#pragma once
#include <CLI/CLI.hpp>
#include <string>

#include "engine/scene.h"
#include "engine/settings.h"

namespace rtfact::app {

struct PointOptions {
    engine::PointSettings settings;
    std::string lod = "on";
    std::string color = "auto";
    std::string range, edl, classes, returns = "all", crop;
    CLI::Option* edlOption = nullptr;

    void addTo(CLI::App& cmd);
    // The settings the parsed options give.
    engine::Settings toSettings() const;
    // The load filters (--classes --returns --crop) for engine::OpenOptions::points.
    points::LoadFilter loadFilter() const;
};

}  // namespace rtfact::app
