// Subcommands of the rtfact CLI. Each registers itself on the app and returns the
// function that runs it once the command line has been parsed.
#pragma once
#include <CLI/CLI.hpp>
#include <functional>
#include <optional>
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

// `rtfact info FILE` asks each domain in turn; a domain returns nullopt for files that
// are not its own, else the exit code after printing.
std::optional<int> volumeInfo(const std::string& file);
std::optional<int> meshInfo(const std::string& file);
std::optional<int> pointsInfo(const std::string& file);

}  // namespace rtfact::app
