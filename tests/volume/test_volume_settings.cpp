// The engine's volume settings reach the volume scene: adaptiveSteps off gives the
// plain march (step multiple 1 everywhere: more samples, a different image), on keeps
// the opacity-adaptive steps; the front ends (CLI --no-adaptive-steps, Python
// no_adaptive_steps) only set this field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/built_scene.h"
#include "engine/render_session.h"
#include "engine/scene.h"
#include "volume/transfer_function.h"

using namespace rtfact;
using namespace rtfact::engine;

namespace {

const std::string kTooth = std::string(RTFACT_DATASETS) + "/volumes/tooth_103x94x161_uint8.mhd";

// A translucent ramp: most bricks stay under the adaptive opacity limit.
Settings translucent(bool adaptive) {
    Settings s;
    volume::TransferFunction tf;
    tf.colors = {{0.0f, {1, 1, 1}}, {1.0f, {1, 0.8f, 0.6f}}};
    tf.opacity = {{0.0f, 0.0f}, {0.3f, 0.0f}, {1.0f, 0.02f}};
    tf.name = "test-translucent";
    s.volume.tf = tf;
    s.volume.adaptiveSteps = adaptive;
    return s;
}

struct Rendered {
    Frame frame;
    uint64_t samples;
};

Rendered render(const Scene& scene, const Settings& settings) {
    FrameOptions fo;
    fo.width = 64;
    fo.height = 48;
    const CameraFrame cam = fitCamera(scene.defaultView(settings), 40.0f, 64.0f / 48.0f);
    Stats stats;
    Frame f = renderToImage(scene, settings, fo, cam, 1, stats);
    return {std::move(f), std::stoull(stats.get("samples"))};
}

}  // namespace

TEST(VolumeSettings, AdaptiveStepsSwitchReachesTheScene) {
    OpenOptions o;
    o.progress = false;
    const Scene scene = open({kTooth}, o);
    EXPECT_EQ(builtVolume(scene, translucent(true)).setup.render.maxStepMultiple, 4);
    EXPECT_EQ(builtVolume(scene, translucent(false)).setup.render.maxStepMultiple, 1);

    const Rendered on = render(scene, translucent(true)), off = render(scene, translucent(false));
    // the plain march takes every sample of the lattice; the adaptive one fewer
    EXPECT_GT(off.samples, on.samples + on.samples / 10);
    ASSERT_EQ(on.frame.rgba.size(), off.frame.rgba.size());
    float maxDiff = 0, maxAlpha = 0;
    for (size_t i = 0; i < on.frame.rgba.size(); ++i) {
        maxDiff = std::max(maxDiff, std::abs(on.frame.rgba[i] - off.frame.rgba[i]));
        maxAlpha = std::max(maxAlpha, off.frame.rgba[i]);
    }
    EXPECT_GT(maxAlpha, 0.05f);  // something visible
    EXPECT_GT(maxDiff, 0.0f);    // different sample sets
    EXPECT_LT(maxDiff, 0.05f);   // of the same picture
}
