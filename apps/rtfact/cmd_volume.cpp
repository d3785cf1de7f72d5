// `rtfact volume FILE`: direct volume rendering (DVR, shaded DVR, MIP, isosurface) of CT,
// MRI and OpenVDB data; `rtfact gen volume ...` synthetic volumes; `rtfact info` for volumes.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/render_command.h"
#include "core/util/error.h"
#include "volume/default_transfer_function.h"
#include "volume/transfer_function.h"
#include "volume/value_histogram.h"
#include "volume/volume_generators.h"
#include "volume/volume_integrator.h"
#include "volume/volume_io.h"
#include "volume/volume_scene.h"

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

void parseClip(const std::string& c, VolumeRenderSettings& s) {
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
        std::string file, tf, mode = "dvr";
        std::optional<float> iso, window, level;
        float step = 0.5f;
        std::vector<std::string> clips;
        bool noSkip = false;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd = app.add_subcommand("volume", "Direct volume rendering of CT/MRI/OpenVDB volumes");
    o->common.addTo(*cmd, "volume.png");
    cmd->add_option("FILE", o->file, "Volume: .raw .mhd/.mha .nrrd/.nhdr .nii[.gz] .vti .vdb or a DICOM directory")
        ->required();
    o->load.addTo(*cmd);
    cmd->add_option("--tf", o->tf,
                    "Transfer function: preset (ct-bone ct-skin ct-muscle mr-default grayscale viridis inferno "
                    "cool-warm) or FILE.json");
    cmd->add_option("--mode", o->mode, "dvr|shaded|mip|iso")
        ->capture_default_str()
        ->check(CLI::IsMember({"dvr", "shaded", "mip", "iso"}));
    cmd->add_option("--iso", o->iso, "Isovalue in data units (iso mode)")->check(finiteNumber());
    cmd->add_option("--step", o->step, "Ray-marching step in voxels")
        ->capture_default_str()
        ->check(finiteRange(0.01, 64.0));
    cmd->add_option("--window", o->window, "Window width in data units (e.g. Hounsfield)")->check(positiveFinite());
    cmd->add_option("--level", o->level, "Window centre in data units")->check(finiteNumber());
    cmd->add_option("--clip", o->clips, "Clip axis:lo:hi (fractions, e.g. z:0:0.5); repeatable")
        ->check(parsedBy(
            [](const std::string& c) {
                VolumeRenderSettings s;
                parseClip(c, s);
            },
            "AXIS:LO:HI"));
    cmd->add_flag("--no-skip", o->noSkip, "Disable empty-space skipping (for comparisons)");
    list.push_back({cmd, [o] {
                        CommonOptions& c = o->common;
                        c.finalize();
                        checkImageWritable(c.out);
                        VolumeRenderSettings rs;
                        rs.mode = o->mode == "shaded" ? VolumeMode::Shaded
                                  : o->mode == "mip"  ? VolumeMode::MIP
                                  : o->mode == "iso"  ? VolumeMode::Iso
                                                      : VolumeMode::DVR;
                        rs.stepVoxels = o->step;
                        rs.skipping = !o->noSkip;
                        for (auto& cl : o->clips) parseClip(cl, rs);
                        // --tf is read before the volume so that a bad file fails fast; without it
                        // the default follows the data (chosen once the volume is loaded).
                        std::optional<TransferFunction> given;
                        if (!o->tf.empty()) given = resolveTransferFunction(o->tf);
                        Stats stats;
                        auto t0 = std::chrono::steady_clock::now();
                        const VolumeLoadOptions lopt = o->load.options(!c.quiet);
                        BrickedVolume vol;
                        const bool sparse =
                            o->load.dims.empty() && o->file.size() > 4 && o->file.substr(o->file.size() - 4) == ".vdb";
                        if (sparse) {
                            // bricked straight from the sparse tree
                            vol = loadBrickedVolume(o->file, lopt);
                            stats.add("load_ms", msSince(t0));
                            t0 = std::chrono::steady_clock::now();
                        } else {
                            VolumeGrid grid = loadVolume(o->file, lopt);
                            stats.add("load_ms", msSince(t0));
                            t0 = std::chrono::steady_clock::now();
                            try {
                                vol = brickVolume(grid, true);
                            } catch (const Error& e) {
                                throw Error(o->file, e.what());
                            }
                        }
                        const auto [lo, hi] = vol.valueRange();
                        TransferFunction tf;
                        std::pair<float, float> window;
                        if (given) {
                            tf = *given;
                            window = resolveWindow(tf, lo, hi, o->window, o->level);
                        } else {
                            const DefaultTransferFunction d = chooseDefaultTransferFunction(
                                vol.meta, histogramOf(vol), rs.mode, typicalDepthVoxels(vol.dims, vol.spacing));
                            tf = d.tf;
                            window = o->window || o->level ? resolveWindow(tf, lo, hi, o->window, o->level) : d.window;
                            stats.add("tf_default", d.describe());
                        }
                        const TFTable table = buildTable(tf, window, o->step);
                        rs.iso = o->iso ? *o->iso : (lo <= -500.0f ? 300.0f : lo + 0.4f * (hi - lo));
                        stats.add("voxels", (unsigned long long)vol.voxelCount());
                        stats.add("bricks_stored", (unsigned long long)vol.storedBricks());
                        stats.add("memory_mb", double(vol.memoryBytes()) / 1048576.0);
                        RenderStats rendered;
                        withVolumeScene(vol, table, rs, [&](const auto& scene) {
                            stats.add("build_ms", msSince(t0));
                            const CameraFrame frame = c.frame(scene.bounds(), {0.45f, -1.0f, 0.35f}, {0, 0, 1});
                            rendered = renderToFile(scene, VolumeIntegrator{}, c, frame, stats);
                        });
                        const double renderMs = rendered.ms;
                        const uint64_t samples = rendered.counters.volumeSamples;
                        const uint64_t skipped = rendered.counters.volumeSkipped;
                        stats.add("samples", (unsigned long long)samples);
                        stats.add("msamples_per_s", renderMs > 0 ? double(samples) / (renderMs * 1000.0) : 0.0);
                        stats.add("skipped_fraction",
                                  samples + skipped ? double(skipped) / double(samples + skipped) : 0.0);
                        stats.add("tf", tf.name);
                        stats.add("window_lo", double(window.first));
                        stats.add("window_hi", double(window.second));
                        if (c.stats) stats.print();
                        return 0;
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

std::optional<int> volumeInfo(const std::string& file) {
    if (!looksLikeVolume(file)) return std::nullopt;
    VolumeLoadOptions lo;
    lo.progress = false;
    const VolumeGrid g = loadVolume(file, lo);
    const VolumeSummary s = summarize(g, 8);
    std::printf(
        "file: %s\nkind: volume\ndims: %d x %d x %d\nvoxels: %zu\ntype: %s (stored as %s, value = stored * %g + %g)\n",
        file.c_str(), g.dims[0], g.dims[1], g.dims[2], g.voxelCount(), g.sourceType.c_str(), storageName(g.storage),
        double(g.scale), double(g.offset));
    std::printf("spacing: %g %g %g\norigin: %g %g %g\n", double(g.spacing.x), double(g.spacing.y), double(g.spacing.z),
                double(g.origin.x), double(g.origin.y), double(g.origin.z));
    const AABB b = g.bounds();
    std::printf("bounds: [%g %g %g] - [%g %g %g]\n", double(b.lo.x), double(b.lo.y), double(b.lo.z), double(b.hi.x),
                double(b.hi.y), double(b.hi.z));
    std::printf("range: %g .. %g (mean %g)\nmemory_mb: %.2f\nhistogram (8 bins over the range, %% of voxels):",
                double(s.lo), double(s.hi), s.mean, double(g.memoryBytes()) / 1048576.0);
    for (uint64_t h : s.histogram)
        std::printf(" %.1f", 100.0 * double(h) / double(std::max<size_t>(g.voxelCount(), 1)));
    std::printf("\n");
    if (!g.meta.modality.empty())
        std::printf("modality: %s (%s)\n", g.meta.modality.c_str(), g.meta.modalitySource.c_str());
    // what `rtfact volume FILE` renders with when no --tf is given
    const DefaultTransferFunction d =
        chooseDefaultTransferFunction(g.meta, histogramOf(g), VolumeMode::DVR, typicalDepthVoxels(g.dims, g.spacing));
    std::printf("tf_default: %s\n", d.describe().c_str());
    return 0;
}

}  // namespace rtfact::app
