// Subcommands of the rtfact CLI. Each registers itself on the app and returns the
// function that runs it once the command line has been parsed.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace rtfact::app {

struct Command {
    CLI::App* cmd;
    std::function<int()> run;
};
using CommandList = std::vector<Command>;

void addSpheresCommand(CLI::App& app, CommandList& list);
void addMeshCommand(CLI::App& app, CommandList& list);
void addPointsCommand(CLI::App& app, CommandList& list);
void addVolumeCommand(CLI::App& app, CommandList& list);
void addGenCommand(CLI::App& app, CommandList& list);
// Generators below `rtfact gen`: `gen points ...` (points/), `gen volume ...` (volume/).
void addGenPointsCommand(CLI::App& gen, CommandList& list);
void addGenVolumeCommand(CLI::App& gen, CommandList& list);
void addInfoCommand(CLI::App& app, CommandList& list);
// `rtfact view`: the browser viewer (apps/view).
void addViewCommand(CLI::App& app, CommandList& list);

// "a|b|c" for option help texts.
inline std::string joined(const std::vector<std::string>& names) {
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : "|") + n;
    return s;
}

}  // namespace rtfact::app
