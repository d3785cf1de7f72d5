// `rtfact points`: placeholder until its issue lands.
#include "apps/rtfact/commands.h"

namespace rtfact::app {

void addPointsCommand(CLI::App&, CommandList&) {}
void addGenPointsCommand(CLI::App&, CommandList&) {}
std::optional<int> pointsInfo(const std::string&) { return std::nullopt; }

}  // namespace rtfact::app
