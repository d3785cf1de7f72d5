// engine::RenderSession: progressive passes add up to a one-shot render, reduced
// resolution, and a second thread changing the camera or cancelling mid-pass.
// Everything is measured in samples and tiles, never in time.
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "engine/render_session.h"
#include "engine/scene.h"

using namespace rtfact;
using namespace rtfact::engine;

namespace {

const std::string kMesh = std::string(RTFACT_DATASETS) + "/meshes/bunny.ply";
const std::string kPoints = std::string(RTFACT_DATASETS) + "/points/bunny_bun000.ply";

Scene openQuiet(const std::string& file) {
    OpenOptions o;
    o.progress = false;
    return open({file}, o);
}

const Scene& bunny() {
    static const Scene s = openQuiet(kMesh);
    return s;
}

FrameOptions size(int w, int h, int threads = 0) {
    FrameOptions fo;
    fo.width = w;
    fo.height = h;
    fo.threads = threads;
    return fo;
}

CameraFrame cameraOf(const Scene& s, Vec3f dir, float aspect = 1.0f) {
    DefaultView v = s.defaultView();
    v.viewDir = dir;
    return fitCamera(v, 45.0f, aspect);
}

Frame oneShot(const Scene& s, const Settings& st, const FrameOptions& fo, const CameraFrame& cam, int spp) {
    Stats stats;
    return renderToImage(s, st, fo, cam, spp, stats);
}

Settings ao() {
    Settings st;
    st.mesh.integrator = "ao";
    st.mesh.aoSamples = 2;
    return st;
}

}  // namespace

// Four one-sample passes accumulate exactly the image of one four-sample render (the
// jittered sampler and AO directions follow the sample index, so passes differ).
TEST(RenderSession, PassesAccumulateToTheOneShotImage) {
    const CameraFrame cam = cameraOf(bunny(), {0.6f, 0.45f, 1.0f});
    RenderSession session(bunny(), ao(), size(48, 40), cam);
    int frames = 0;
    session.onFrame([&](const Frame& f) { EXPECT_EQ(f.samples, ++frames); });
    for (int i = 1; i <= 4; ++i) {
        const PassResult r = session.renderPass();
        EXPECT_EQ(r.status, PassResult::Status::Done);
        EXPECT_EQ(r.samples, i);
    }
    EXPECT_EQ(frames, 4);
    const Frame four = oneShot(bunny(), ao(), size(48, 40), cam, 4);
    EXPECT_EQ(session.frame().rgba, four.rgba);
    EXPECT_NE(oneShot(bunny(), ao(), size(48, 40), cam, 1).rgba, four.rgba);
}

TEST(RenderSession, PointPassesAccumulateToTheOneShotImage) {
    const Scene pts = openQuiet(kPoints);
    Settings st;
    st.points.integrator = "ao";
    st.points.aoSamples = 2;
    const CameraFrame cam = cameraOf(pts, {0.6f, 0.45f, 1.0f});
    RenderSession session(pts, st, size(40, 32), cam);
    session.renderPass();
    session.renderPass();
    EXPECT_EQ(session.samples(), 2);
    EXPECT_EQ(session.frame().rgba, oneShot(pts, st, size(40, 32), cam, 2).rgba);
    EXPECT_NE(session.stats().get("lod_nodes_hit"), "");
}

TEST(RenderSession, ReducedResolutionRestartsAndMatchesTheSmallImage) {
    const CameraFrame cam = cameraOf(bunny(), {0.6f, 0.45f, 1.0f});
    RenderSession session(bunny(), {}, size(64, 48), cam);
    session.renderPass();
    session.renderPass();
    EXPECT_EQ(session.samples(), 2);
    session.setScale(4);
    EXPECT_EQ(session.width(), 16);
    EXPECT_EQ(session.height(), 12);
    EXPECT_EQ(session.samples(), 2);  // restarts with the next pass
    EXPECT_EQ(session.renderPass().samples, 1);
    const Frame f = session.frame();
    EXPECT_EQ(f.width, 16);
    EXPECT_EQ(f.height, 12);
    EXPECT_EQ(f.rgba, oneShot(bunny(), {}, size(16, 12), cam, 1).rgba);
    session.setScale(1);
    EXPECT_EQ(session.renderPass().samples, 1);
    EXPECT_EQ(session.frame().rgba, oneShot(bunny(), {}, size(64, 48), cam, 1).rgba);
}

TEST(RenderSession, SettingsChangeRestarts) {
    const CameraFrame cam = cameraOf(bunny(), {0.6f, 0.45f, 1.0f});
    RenderSession session(bunny(), {}, size(32, 32), cam);
    session.renderPass();
    session.renderPass();
    Settings eye;
    eye.mesh.integrator = "eyelight";
    session.setSettings(eye);
    EXPECT_EQ(session.renderPass().samples, 1);
    EXPECT_EQ(session.frame().rgba, oneShot(bunny(), eye, size(32, 32), cam, 1).rgba);
}

// restart() keeps the view and starts its samples over: the next pass is sample 1 and its
// image that of a one-sample render.
TEST(RenderSession, RestartStartsTheSamplesOver) {
    const CameraFrame cam = cameraOf(bunny(), {0.6f, 0.45f, 1.0f});
    RenderSession session(bunny(), ao(), size(32, 32), cam);
    session.renderPass();
    EXPECT_EQ(session.renderPass().samples, 2);
    session.restart();
    EXPECT_EQ(session.samples(), 2);  // the accumulated image stays until the next pass
    EXPECT_EQ(session.renderPass().samples, 1);
    EXPECT_EQ(session.frame().rgba, oneShot(bunny(), ao(), size(32, 32), cam, 1).rgba);
    EXPECT_EQ(session.renderPass().samples, 2);
}

// Thread B changes the camera while thread A is inside a pass (A's worker is held in
// the tile callback until B has made the change): that pass is abandoned, no tile
// starts after the change, and the next frame shows the new camera.
TEST(RenderSession, CameraChangeFromAnotherThreadMidPass) {
    const CameraFrame camA = cameraOf(bunny(), {0.6f, 0.45f, 1.0f}), camB = cameraOf(bunny(), {-1.0f, 0.2f, -0.3f});
    // 128x128 in 32-pixel tiles: 16 tiles a pass; one render thread, so the order is fixed.
    RenderSession session(bunny(), {}, size(128, 128, 1), camA);
    std::mutex m;
    std::condition_variable cv;
    bool reached = false, changed = false;
    std::atomic<bool> armed{true};
    std::atomic<int> tiles{0}, tilesAfterChange{0};
    session.onProgress([&](uint64_t done, uint64_t total) {
        EXPECT_EQ(total, 16u);
        ++tiles;
        if (changed) ++tilesAfterChange;
        if (done == 5 && armed.exchange(false)) {
            std::unique_lock l(m);
            reached = true;
            cv.notify_all();
            cv.wait(l, [&] { return changed; });
        }
    });
    std::thread b([&] {
        std::unique_lock l(m);
        cv.wait(l, [&] { return reached; });
        session.setCamera(camB);
        changed = true;
        cv.notify_all();
    });
    const PassResult interrupted = session.renderPass();
    b.join();
    EXPECT_EQ(interrupted.status, PassResult::Status::Restarted);
    EXPECT_EQ(tiles.load(), 5);             // stopped at the tile where the camera changed
    EXPECT_EQ(tilesAfterChange.load(), 0);  // not one tile more
    EXPECT_EQ(session.samples(), 0);
    const PassResult next = session.renderPass();
    EXPECT_EQ(next.status, PassResult::Status::Done);
    EXPECT_EQ(next.samples, 1);
    const Frame f = session.frame();
    EXPECT_EQ(f.rgba, oneShot(bunny(), {}, size(128, 128), camB, 1).rgba);
    EXPECT_NE(f.rgba, oneShot(bunny(), {}, size(128, 128), camA, 1).rgba);
}

// cancel() from another thread with two render threads: the pass returns Cancelled
// after at most the one tile the other worker had in flight; the accumulation keeps
// the completed passes and goes on from them.
TEST(RenderSession, CancelFromAnotherThreadStopsWithinOneTile) {
    const CameraFrame cam = cameraOf(bunny(), {0.6f, 0.45f, 1.0f});
    RenderSession session(bunny(), ao(), size(128, 128, 2), cam);
    ASSERT_EQ(session.renderPass().samples, 1);
    std::mutex m;
    std::condition_variable cv;
    bool reached = false;
    std::atomic<bool> armed{true}, cancelled{false};
    std::atomic<int> tiles{0}, tilesAfterCancel{0};
    // Every tile finished after the third waits for the cancel: otherwise the other worker
    // could render all the rest before thread b wakes up (it did, once the mesh got faster).
    session.onProgress([&](uint64_t done, uint64_t) {
        ++tiles;
        if (cancelled) ++tilesAfterCancel;
        std::unique_lock l(m);
        if (done == 3 && armed.exchange(false)) {
            reached = true;
            cv.notify_all();
        }
        if (reached) cv.wait(l, [&] { return cancelled.load(); });
    });
    std::thread b([&] {
        std::unique_lock l(m);
        cv.wait(l, [&] { return reached; });
        session.cancel();
        cancelled = true;
        cv.notify_all();
    });
    const PassResult r = session.renderPass();
    b.join();
    EXPECT_EQ(r.status, PassResult::Status::Cancelled);
    EXPECT_TRUE(r.render.cancelled);
    EXPECT_LE(tilesAfterCancel.load(), 1);  // the other worker's tile in flight
    EXPECT_LT(tiles.load(), 16);
    EXPECT_EQ(r.samples, 1);
    EXPECT_EQ(session.samples(), 1);
    session.onProgress(nullptr);
    EXPECT_EQ(session.renderPass().samples, 2);
    EXPECT_EQ(session.frame().rgba, oneShot(bunny(), ao(), size(128, 128), cam, 2).rgba);
}

// Each tile clears its own pixels as it renders them: a first pass of a new camera that is
// cancelled part way leaves the old camera's colours and depth in the tiles it did not
// reach, and the next pass must still give the new camera's image, eye-dome lighting (from
// the depth) included.
TEST(RenderSession, CancelledFirstPassLeavesNoStaleDepth) {
    const Scene pts = openQuiet(kPoints);
    const Settings st;  // a cloud without normals: eye-dome lighting on, so a depth channel
    const CameraFrame camA = cameraOf(pts, {0.6f, 0.45f, 1.0f}), camB = cameraOf(pts, {-1.0f, 0.2f, -0.3f});
    RenderSession session(pts, st, size(128, 128, 1), camA);
    EXPECT_EQ(session.renderPass().status, PassResult::Status::Done);
    session.setCamera(camB);
    session.onProgress([&](uint64_t done, uint64_t) {
        if (done == 3) session.cancel();
    });
    EXPECT_EQ(session.renderPass().status, PassResult::Status::Cancelled);
    EXPECT_EQ(session.samples(), 0);
    session.onProgress(nullptr);
    EXPECT_EQ(session.renderPass().samples, 1);
    const Frame f = session.frame();
    const Frame b = oneShot(pts, st, size(128, 128), camB, 1);
    ASSERT_EQ(f.rgba.size(), b.rgba.size());
    EXPECT_EQ(f.rgba, b.rgba);
}

// Shaded volumes: a settings change that shows no new brick (here the step) takes the
// last scene's gradient bricks instead of rebuilding them, and the image is that of a
// freshly opened scene (no bricks to reuse).
TEST(RenderSession, ShadedVolumeReusesGradientBricks) {
    const std::string tooth = std::string(RTFACT_DATASETS) + "/volumes/tooth_103x94x161_uint8.mhd";
    const Scene s = openQuiet(tooth);
    Settings shaded;
    shaded.volume.mode = "shaded";
    const CameraFrame cam = cameraOf(s, {0.6f, 0.45f, 1.0f});
    RenderSession session(s, shaded, size(48, 48), cam);
    session.renderPass();
    EXPECT_EQ(session.buildStats().get("gradients_reused"), "0");
    EXPECT_GT(std::stod(session.buildStats().get("gradient_mb")), 0.0);
    Settings finer = shaded;
    finer.volume.step = 0.7f;
    session.setSettings(finer);
    session.renderPass();
    EXPECT_EQ(session.buildStats().get("gradients_reused"), "1");
    EXPECT_EQ(session.frame().rgba, oneShot(openQuiet(tooth), finer, size(48, 48), cam, 1).rgba);
}
