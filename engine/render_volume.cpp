// Volumes: the mode table (dvr | shaded | mip | iso), the transfer function (given, or
// the default chosen from the data), window/level, the iso default and the volume scene
// per storage type.
#include <chrono>

#include "engine/built_scene.h"
#include "engine/renderable.h"
#include "volume/default_transfer_function.h"
#include "volume/value_histogram.h"
#include "volume/volume_integrator.h"
#include "volume/volume_scene.h"

namespace rtfact::engine {

const std::vector<std::string>& volumeModes() {
    static const std::vector<std::string> names{"dvr", "shaded", "mip", "iso"};
    return names;
}

namespace detail {

using namespace rtfact::volume;

namespace {

VolumeMode modeOf(const std::string& name) {
    return name == "shaded" ? VolumeMode::Shaded
           : name == "mip"  ? VolumeMode::MIP
           : name == "iso"  ? VolumeMode::Iso
                            : VolumeMode::DVR;
}

// Default isovalue: bone for CT in Hounsfield units, else 40% up the value range.
float defaultIso(float lo, float hi) { return lo <= -500.0f ? 300.0f : lo + 0.4f * (hi - lo); }

template <class T>
std::unique_ptr<Renderable> make(const BrickedVolume& v, const TFTable& table, const VolumeRenderSettings& rs,
                                 const TransferFunction& tf, std::pair<float, float> window, Stats& stats,
                                 std::shared_ptr<const GradientBricks>& gradientCache) {
    auto scene = std::make_shared<VolumeScene<T>>(v, table, rs, gradientCache);
    if (rs.mode == VolumeMode::Shaded) {
        // the gradient bricks' memory (0: six samples a gradient), and whether the last
        // shaded scene's were taken
        const bool reused = scene->gradients && scene->gradients == gradientCache;
        stats.add("gradient_mb", scene->gradients ? double(scene->gradients->memoryBytes()) / 1048576.0 : 0.0);
        stats.add("gradients_reused", (unsigned long long)(reused ? 1 : 0));
        if (scene->gradients) gradientCache = scene->gradients;
    }
    auto r = std::make_unique<RenderableOf<VolumeScene<T>, VolumeIntegrator>>(scene, VolumeIntegrator{});
    r->stats = [name = tf.name, window](Stats& st, const RenderStats& rst) {
        const uint64_t samples = rst.counters.volumeSamples, skipped = rst.counters.volumeSkipped;
        st.add("samples", (unsigned long long)samples);
        st.add("msamples_per_s", rst.ms > 0 ? double(samples) / (rst.ms * 1000.0) : 0.0);
        st.add("skipped_fraction", samples + skipped ? double(skipped) / double(samples + skipped) : 0.0);
        st.add("tf", name);
        st.add("window_lo", double(window.first));
        st.add("window_hi", double(window.second));
    };
    return r;
}

}  // namespace

VolumeSetup resolveVolumeSetup(const BrickedVolume& vol, const VolumeSettings& s, Stats& stats) {
    requireName(volumeModes(), s.mode, "--mode");
    VolumeRenderSettings rs;
    rs.mode = modeOf(s.mode);
    rs.stepVoxels = s.step;
    rs.skipping = s.skipping;
    if (!s.adaptiveSteps) rs.maxStepMultiple = 1;
    rs.preintegrated = s.preintegrated;
    rs.clipLo = s.clipLo;
    rs.clipHi = s.clipHi;
    if (s.lattice) {
        rs.lattice = true;
        rs.latticeLo = s.lattice->lo;
        rs.latticeHi = s.lattice->hi;
    }
    const auto [lo, hi] = vol.valueRange();
    TransferFunction tf;
    std::pair<float, float> window;
    if (s.tf) {
        tf = *s.tf;
        window = resolveWindow(tf, lo, hi, s.window, s.level);
    } else {
        const DefaultTransferFunction dt = chooseDefaultTransferFunction(vol.meta, histogramOf(vol), rs.mode,
                                                                         typicalDepthVoxels(vol.dims, vol.spacing));
        tf = dt.tf;
        window = s.window || s.level ? resolveWindow(tf, lo, hi, s.window, s.level) : dt.window;
        stats.add("tf_default", dt.describe());
    }
    rs.iso = s.iso ? *s.iso : defaultIso(lo, hi);
    return {rs, tf, window, buildTable(tf, window, s.step)};
}

std::unique_ptr<Renderable> makeVolumeRenderable(SceneData& d, const VolumeSettings& s, Stats& stats) {
    const BrickedVolume& vol = d.volume.vol;
    const auto t0 = std::chrono::steady_clock::now();
    const VolumeSetup vs = resolveVolumeSetup(vol, s, stats);
    const VolumeRenderSettings& rs = vs.render;
    const TransferFunction& tf = vs.tf;
    const std::pair<float, float> window = vs.window;
    const TFTable& table = vs.table;
    stats.add("voxels", (unsigned long long)vol.voxelCount());
    stats.add("bricks_stored", (unsigned long long)vol.storedBricks());
    stats.add("memory_mb", double(vol.memoryBytes()) / 1048576.0);
    std::unique_ptr<Renderable> r;
    switch (vol.storage) {
        case Storage::U8:
            r = make<uint8_t>(vol, table, rs, tf, window, stats, d.volume.gradients);
            break;
        case Storage::U16:
            r = make<uint16_t>(vol, table, rs, tf, window, stats, d.volume.gradients);
            break;
        default:
            r = make<float>(vol, table, rs, tf, window, stats, d.volume.gradients);
            break;
    }
    stats.add("build_ms", msSince(t0));
    return r;
}

}  // namespace detail

BuiltVolume builtVolume(const Scene& scene, const Settings& settings, Stats* stats) {
    const detail::SceneData& d = *scene.data;
    if (d.kind != SceneKind::Volume) throw UsageError("scene", "builtVolume needs a volume");
    Stats ignored;
    return {&d.volume.vol, detail::resolveVolumeSetup(d.volume.vol, settings.volume, stats ? *stats : ignored)};
}

}  // namespace rtfact::engine
