// `rtfact info FILE`: what a file holds, as the engine describes it.
#include <cstdio>

#include "apps/rtfact/commands.h"
#include "engine/scene.h"

namespace rtfact::app {

void addInfoCommand(CLI::App& app, CommandList& list) {
    auto file = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("info", "Print what a mesh, point cloud or volume file holds");
    cmd->add_option("FILE", *file, "Input file (or DICOM directory)")->required();
    list.push_back({cmd, [file] {
                        for (const auto& [key, value] : engine::fileInfo(*file))
                            std::printf("%s:%s%s\n", key.c_str(), value.empty() ? "" : " ", value.c_str());
                        return 0;
                    }});
}

}  // namespace rtfact::app
