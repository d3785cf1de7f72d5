// `rtfact gen ...`: data generators; each domain adds its own generator subcommand.
#include "apps/rtfact/commands.h"

namespace rtfact::app {

void addGenCommand(CLI::App& app, CommandList& list) {
    CLI::App* gen = app.add_subcommand("gen", "Generate data sets (point clouds from meshes, synthetic volumes)");
    gen->require_subcommand(1);
    addGenPointsCommand(*gen, list);
    addGenVolumeCommand(*gen, list);
}

}  // namespace rtfact::app
