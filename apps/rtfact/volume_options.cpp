#include "apps/rtfact/volume_options.h"

#include <cstdio>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/common_options.h"
#include "core/util/error.h"
#include "engine/setting_text.h"
#include "volume/transfer_function.h"
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

}  // namespace

void VolumeOptions::addTo(CLI::App& cmd) {
    cmd.add_option("--dims", dims, "Raw volume size X,Y,Z")->check(parsedBy(parseDims, "X,Y,Z"));
    cmd.add_option("--type", type, "Raw voxel type u8|u16|i16|f32")->check(CLI::IsMember({"u8", "u16", "i16", "f32"}));
    cmd.add_option("--endian", endian, "Raw byte order little|big")
        ->capture_default_str()
        ->check(CLI::IsMember({"little", "big"}));
    cmd.add_option("--spacing", spacing, "Voxel spacing sx,sy,sz (overrides the file's)")
        ->check(parsedBy(parseSpacing, "SX,SY,SZ"));
    cmd.add_option("--header-skip", headerSkip, "Raw bytes to skip before the voxels");
    cmd.add_option("--grid", grid, "OpenVDB grid name (default: the first float grid)");
    cmd.add_option("--tf", tf,
                   "Transfer function: preset (ct-bone ct-skin ct-muscle mr-default grayscale viridis inferno "
                   "cool-warm) or FILE.json");
    cmd.add_option("--mode", settings.mode, joined(engine::volumeModes()))
        ->capture_default_str()
        ->check(CLI::IsMember(engine::volumeModes()));
    cmd.add_option("--iso", settings.iso, "Isovalue in data units (iso mode)")->check(finiteNumber());
    cmd.add_option("--step", settings.step, "Ray-marching step in voxels")
        ->capture_default_str()
        ->check(finiteRange(0.01, 64.0));
    cmd.add_option("--window", settings.window, "Window width in data units (e.g. Hounsfield)")
        ->check(positiveFinite());
    cmd.add_option("--level", settings.level, "Window centre in data units")->check(finiteNumber());
    cmd.add_option("--clip", clips, "Clip axis:lo:hi (fractions, e.g. z:0:0.5); repeatable")
        ->check(parsedBy(
            [](const std::string& c) {
                engine::VolumeSettings s;
                engine::applyClipText(c, s, "--clip");
            },
            "AXIS:LO:HI"));
    cmd.add_flag("--no-skip", noSkip, "Disable empty-space skipping (for comparisons)");
    cmd.add_flag("--no-adaptive-steps", noAdaptiveSteps,
                 "March low-opacity bricks with the plain step too (no 2x/4x steps)");
    cmd.add_flag("--preintegrated", settings.preintegrated,
                 "Pre-integrated TF (dvr, shaded): each step composites the values between two samples, "
                 "so narrow TF bands stay whole at long steps");
}

engine::Settings VolumeOptions::toSettings() const {
    engine::Settings s;
    s.volume = settings;
    s.volume.skipping = !noSkip;
    s.volume.adaptiveSteps = !noAdaptiveSteps;
    for (const std::string& cl : clips) engine::applyClipText(cl, s.volume, "--clip");
    // --tf is read before the volume so that a bad file fails fast; without it the
    // engine chooses the default from the data.
    if (!tf.empty()) s.volume.tf = resolveTransferFunction(tf);
    return s;
}

engine::OpenOptions VolumeOptions::openOptions(bool progress) const {
    engine::OpenOptions oo;
    oo.kind = engine::SceneKind::Volume;
    oo.progress = progress;
    VolumeLoadOptions& o = oo.volume;
    if (!dims.empty()) o.dims = parseDims(dims);
    o.type = type;
    o.endian = endian;
    if (!spacing.empty()) o.spacing = parseSpacing(spacing);
    o.headerSkip = headerSkip;
    o.grid = grid;
    o.progress = progress;
    return oo;
}

}  // namespace rtfact::app
