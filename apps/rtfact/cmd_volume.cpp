// `rtfact volume FILE`: direct volume rendering (DVR, shaded DVR, MIP, isosurface) of CT,
// MRI and OpenVDB data through the engine; `rtfact gen volume ...` synthetic volumes.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/render_command.h"
#include "apps/rtfact/volume_options.h"
#include "core/util/error.h"
#include "volume/transfer_function.h"
#include "volume/volume_generators.h"
#include "volume/volume_io.h"

namespace rtfact::app {

using namespace rtfact::volume;

void addVolumeCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        std::string file;
        VolumeOptions volume;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd = app.add_subcommand("volume", "Direct volume rendering of CT/MRI/OpenVDB volumes");
    o->common.addTo(*cmd, "volume.png");
    cmd->add_option("FILE", o->file, "Volume: .raw .mhd/.mha .nrrd/.nhdr .nii[.gz] .vti .vdb or a DICOM directory")
        ->required();
    o->volume.addTo(*cmd);
    list.push_back({cmd, [o] {
                        const DataSource data{engine::SceneKind::Volume, o->file,
                                              [&] { return o->volume.openOptions(!o->common.quiet); }};
                        return runRenderCommand(
                            o->common, [&] { return o->volume.toSettings(); },
                            [&] { return engine::open({o->file}, o->volume.openOptions(!o->common.quiet)); }, &data);
                    }});
}

void addGenVolumeCommand(CLI::App& gen, CommandList& list) {
    struct Opts {
        std::string kind, out, type = "u16";
        int size = 128, thickness = 32;
        bool quiet = false;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd = gen.add_subcommand("volume", "Synthetic volumes: 3D Shepp-Logan phantom or a homogeneous slab");
    cmd->add_option("KIND", o->kind, "phantom|slab")->required()->check(CLI::IsMember({"phantom", "slab"}));
    cmd->add_option("-o,--out", o->out, "Output .mhd (with a .raw next to it) or .raw")->required();
    cmd->add_option("--size", o->size, "Voxels per axis")->capture_default_str()->check(CLI::Range(2, 2048));
    cmd->add_option("--type", o->type, "phantom voxel type u8|u16")
        ->capture_default_str()
        ->check(CLI::IsMember({"u8", "u16"}));
    cmd->add_option("--thickness", o->thickness, "slab thickness along z in voxels")
        ->capture_default_str()
        ->check(CLI::Range(1, 2047));
    cmd->add_flag("--quiet", o->quiet, "No progress output");
    list.push_back({cmd, [o] {
                        VolumeGrid g;
                        if (o->kind == "phantom") {
                            g = makeSheppLogan(o->size, o->type == "u8" ? Storage::U8 : Storage::U16);
                        } else {
                            const int z0 = (o->size - 1 - o->thickness) / 2;
                            g = makeSlab(o->size, o->size, o->size, z0, z0 + o->thickness, 255);
                            if (!o->quiet)
                                std::printf(
                                    "slab: value 255 for z in [%d, %d] (%d voxels thick along z), 0 elsewhere; "
                                    "a TF of opacity a per voxel gives transmittance (1-a)^%d along z\n",
                                    z0, z0 + o->thickness, o->thickness, o->thickness);
                        }
                        const std::string ext = std::filesystem::path(o->out).extension().string();
                        if (ext == ".mhd")
                            writeMetaImage(o->out, g);
                        else if (ext == ".raw")
                            writeRaw(o->out, g);
                        else
                            throw Error(o->out, "output must end in .mhd or .raw");
                        if (!o->quiet)
                            std::printf("wrote %s: %dx%dx%d %s\n", o->out.c_str(), g.dims[0], g.dims[1], g.dims[2],
                                        storageName(g.storage));
                        return 0;
                    }});
}

}  // namespace rtfact::app
