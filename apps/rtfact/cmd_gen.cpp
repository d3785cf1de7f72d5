// `rtfact gen`: data generators (placeholder until the domain issues add theirs).
#include "apps/rtfact/commands.h"

namespace rtfact::app {

void addGenCommand(CLI::App&, CommandList&) {}

}  // namespace rtfact::app
