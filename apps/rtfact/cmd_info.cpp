// `rtfact info FILE`: what a file holds, asked of each domain in turn.
#include "apps/rtfact/commands.h"
#include "core/util/error.h"
#include "core/util/input_file.h"

namespace rtfact::app {

void addInfoCommand(CLI::App& app, CommandList& list) {
    auto file = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("info", "Print what a mesh, point cloud or volume file holds");
    cmd->add_option("FILE", *file, "Input file (or DICOM directory)")->required();
    list.push_back({cmd, [file] {
                        // Before any domain opens it: a named pipe would block every reader.
                        requireFileOrDirectory(*file);
                        if (auto r = volumeInfo(*file)) return *r;
                        if (auto r = meshInfo(*file)) return *r;
                        if (auto r = pointsInfo(*file)) return *r;
                        throw Error(*file, "unknown file type");
                    }});
}

}  // namespace rtfact::app
