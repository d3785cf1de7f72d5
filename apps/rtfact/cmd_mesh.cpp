// `rtfact mesh`: placeholder until its issue lands.
#include "apps/rtfact/commands.h"

namespace rtfact::app {

void addMeshCommand(CLI::App&, CommandList&) {}
std::optional<int> meshInfo(const std::string&) { return std::nullopt; }

}  // namespace rtfact::app
