// rtfact: one command line for every renderer. It parses, loads, composes, renders and
// writes; the work lives in the libraries.
#include <cstdio>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/outcome.h"

int main(int argc, char** argv) {
    using namespace rtfact::app;
    CLI::App app{"rtfact - fast CPU ray tracing of point clouds, volumes and surfaces", "rtfact"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "rtfact 0.1.0");
    CommandList commands;
    addSpheresCommand(app, commands);
    addMeshCommand(app, commands);
    addPointsCommand(app, commands);
    addVolumeCommand(app, commands);
    addGenCommand(app, commands);
    addInfoCommand(app, commands);
    addViewCommand(app, commands);
    try {
        app.parse(argc, argv);
        for (Command& c : commands)
            if (c.cmd->parsed()) return c.run();
        return 2;
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (...) {
        // Usage errors point to the help; the rest is one line naming the source.
        const Outcome o = currentOutcome();
        std::fprintf(stderr, "rtfact: error: %s\n%s", o.message.c_str(), o.status == 2 ? "(see rtfact --help)\n" : "");
        return o.status;
    }
}
