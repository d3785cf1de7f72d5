// The options of `rtfact volume`: how a raw/VDB file is read (dims, type, spacing, grid)
// and how it is rendered (mode, TF, window/level, step, clips), shared by every command
// that renders volumes (volume, view).
#pragma once
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/scene.h"
#include "engine/settings.h"

namespace rtfact::app {

struct VolumeOptions {
    // Reading
    std::string dims, type, endian = "little", spacing, grid;
    uint64_t headerSkip = 0;
    // Rendering
    std::string tf;
    engine::VolumeSettings settings;
    std::vector<std::string> clips;
    bool noSkip = false;
    bool noAdaptiveSteps = false;

    void addTo(CLI::App& cmd);
    // The settings the parsed options give (reads a --tf file).
    engine::Settings toSettings() const;
    // How to open the file.
    engine::OpenOptions openOptions(bool progress) const;
};

}  // namespace rtfact::app
