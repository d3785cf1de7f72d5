// `rtfact volume FILE`: direct volume rendering (DVR, shaded DVR, MIP, isosurface) of CT,
// MRI and OpenVDB data through the engine; `rtfact gen volume ...` synthetic volumes.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/render_command.h"
#include "core/util/error.h"
#include "volume/transfer_function.h"
#include "volume/volume_generators.h"
#include "volume/volume_io.h"

namespace rtfact::app {

using namespace rtfact::volume;

namespace {

// A CLI11 validator from a parser that throws rtfact::Error: bad values are bad usage
// (exit 2, "--dims: ..."), found while parsing the command line, before any loading.
template <class Parse>
CLI::Validator parsedBy(Parse parse, std::string description) {
    return CLI::Validator(
        [parse](std::string& text) -> std::string {
            try {
                parse(text);
            } catch (const Error& e) {
                return e.what();
            }
            return std::string();
        },
        std::move(description));
}

struct LoadArgs {
    std::string dims, type, endian = "little", spacing, grid;
    uint64_t headerSkip = 0;
    void addTo(CLI::App& cmd) {
        cmd.add_option("--dims", dims, "Raw volume size X,Y,Z")->check(parsedBy(parseDims, "X,Y,Z"));
        cmd.add_option("--type", type, "Raw voxel type u8|u16|i16|f32")
            ->check(CLI::IsMember({"u8", "u16", "i16", "f32"}));
        cmd.add_option("--endian", endian, "Raw byte order little|big")
            ->capture_default_str()
            ->check(CLI::IsMember({"little", "big"}));
        cmd.add_option("--spacing", spacing, "Voxel spacing sx,sy,sz (overrides the file's)")
            ->check(parsedBy(parseSpacing, "SX,SY,SZ"));
        cmd.add_option("--header-skip", headerSkip, "Raw bytes to skip before the voxels");
        cmd.add_option("--grid", grid, "OpenVDB grid name (default: the first float grid)");
    }
    VolumeLoadOptions options(bool progress) const {
        VolumeLoadOptions o;
        if (!dims.empty()) o.dims = parseDims(dims);
        o.type = type;
        o.endian = endian;
        if (!spacing.empty()) o.spacing = parseSpacing(spacing);
        o.headerSkip = headerSkip;
        o.grid = grid;
        o.progress = progress;
        return o;
    }
};

void parseClip(const std::string& c, engine::VolumeSettings& s) {
    // axis:lo:hi with axis x|y|z and lo, hi fractions of the axis in [0, 1]
    char axis = 0;
    float lo = 0, hi = 0;
    char tail = 0;
    if (std::sscanf(c.c_str(), "%c:%f:%f%c", &axis, &lo, &hi, &tail) != 3 ||
        (axis != 'x' && axis != 'y' && axis != 'z') || !(lo >= 0 && hi <= 1 && lo < hi))
        throw Error("--clip", "expected axis:lo:hi with axis x|y|z and 0 <= lo < hi <= 1, got '" + c + "'");
    const int a = axis - 'x';
    s.clipLo[a] = lo;
    s.clipHi[a] = hi;
}

}  // namespace

void addVolumeCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        LoadArgs load;
        std::string file, tf;
        engine::VolumeSettings settings;
        std::vector<std::string> clips;
        bool noSkip = false;
    };
    auto o = std::make_shared<Opts>();
    engine::VolumeSettings& vs = o->settings;
    CLI::App* cmd = app.add_subcommand("volume", "Direct volume rendering of CT/MRI/OpenVDB volumes");
    o->common.addTo(*cmd, "volume.png");
    cmd->add_option("FILE", o->file, "Volume: .raw .mhd/.mha .nrrd/.nhdr .nii[.gz] .vti .vdb or a DICOM directory")
        ->required();
    o->load.addTo(*cmd);
    cmd->add_option("--tf", o->tf,
                    "Transfer function: preset (ct-bone ct-skin ct-muscle mr-default grayscale viridis inferno "
                    "cool-warm) or FILE.json");
    cmd->add_option("--mode", vs.mode, joined(engine::volumeModes()))
        ->capture_default_str()
        ->check(CLI::IsMember(engine::volumeModes()));
    cmd->add_option("--iso", vs.iso, "Isovalue in data units (iso mode)")->check(finiteNumber());
    cmd->add_option("--step", vs.step, "Ray-marching step in voxels")
        ->capture_default_str()
        ->check(finiteRange(0.01, 64.0));
    cmd->add_option("--window", vs.window, "Window width in data units (e.g. Hounsfield)")->check(positiveFinite());
    cmd->add_option("--level", vs.level, "Window centre in data units")->check(finiteNumber());
    cmd->add_option("--clip", o->clips, "Clip axis:lo:hi (fractions, e.g. z:0:0.5); repeatable")
        ->check(parsedBy(
            [](const std::string& c) {
                engine::VolumeSettings s;
                parseClip(c, s);
            },
            "AXIS:LO:HI"));
    cmd->add_flag("--no-skip", o->noSkip, "Disable empty-space skipping (for comparisons)");
    list.push_back({cmd, [o] {
                        return runRenderCommand(
                            o->common,
                            [&] {
                                engine::Settings s;
                                s.volume = o->settings;
                                s.volume.skipping = !o->noSkip;
                                for (const std::string& cl : o->clips) parseClip(cl, s.volume);
                                // --tf is read before the volume so that a bad file fails fast; without
                                // it the engine chooses the default from the data.
                                if (!o->tf.empty()) s.volume.tf = resolveTransferFunction(o->tf);
                                return s;
                            },
                            [&] {
                                engine::OpenOptions oo;
                                oo.kind = engine::SceneKind::Volume;
                                oo.volume = o->load.options(!o->common.quiet);
                                oo.progress = !o->common.quiet;
                                return engine::open({o->file}, oo);
                            });
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
