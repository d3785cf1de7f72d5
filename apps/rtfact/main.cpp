// rtfact: one command line for every renderer. It parses, loads, composes, renders and
// writes; the work lives in the libraries.
#include <cstdio>
#include <exception>

#include "apps/rtfact/commands.h"
#include "core/util/error.h"
#include "engine/usage_error.h"

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
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "rtfact: error: %s\n(see rtfact --help)\n", e.what());
        return 2;
    } catch (const rtfact::engine::UsageError& e) {
        std::fprintf(stderr, "rtfact: error: %s\n(see rtfact --help)\n", e.message().c_str());
        return 2;
    } catch (const rtfact::Error& e) {
        std::fprintf(stderr, "rtfact: error: %s\n", e.message().c_str());
        return 1;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "rtfact: error: out of memory\n");
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rtfact: error: %s\n", e.what());
        return 1;
    }
}
