// `rtfact volume`: placeholder until its issue lands.
#include "apps/rtfact/commands.h"

namespace rtfact::app {

void addVolumeCommand(CLI::App&, CommandList&) {}
void addGenVolumeCommand(CLI::App&, CommandList&) {}
std::optional<int> volumeInfo(const std::string&) { return std::nullopt; }

}  // namespace rtfact::app
