// ClientSession without a network: frames wait for the page's acknowledgement, and a
// frame waiting is replaced by a newer one (the page never receives a stale picture).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "apps/view/client_session.h"
#include "tests/viewer/camera_message.h"

using namespace rtfact;
using namespace rtfact::viewer;
using nlohmann::json;

namespace {

struct Capture {
    std::mutex m;
    std::vector<json> texts, frames;
    ClientSession::Output output() {
        return {[this](std::string t) {
                    std::lock_guard l(m);
                    texts.push_back(json::parse(t));
                },
                [this](std::string meta, std::vector<uint8_t>) {
                    std::lock_guard l(m);
                    frames.push_back(json::parse(meta));
                }};
    }
    size_t count() {
        std::lock_guard l(m);
        return frames.size();
    }
    json frame(size_t i) {
        std::lock_guard l(m);
        return frames.at(i);
    }
};

// Bounded wait for a state the session reaches by itself.
template <class F>
bool eventually(F f) {
    for (int i = 0; i < 2400; ++i) {
        if (f()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    return f();
}

engine::Scene bunny() {
    engine::OpenOptions o;
    o.progress = false;
    return engine::open({std::string(RTFACT_DATASETS) + "/meshes/bunny.ply"}, o);
}

// A 32x32 tab that stops at one sample.
ViewerConfig oneSampleConfig(const engine::Scene& scene) {
    ViewerConfig cfg;
    cfg.frame.width = 32;
    cfg.frame.height = 32;
    cfg.home = engine::fitCamera(scene.defaultView(), 45.0f, 1.0f);
    cfg.maxSamples = 1;
    return cfg;
}

}  // namespace

TEST(ClientSession, FramesWaitForTheAckAndOnlyTheNewestWaits) {
    const engine::Scene scene = bunny();
    ViewerConfig cfg;
    cfg.frame.width = 64;
    cfg.frame.height = 48;
    cfg.home = engine::fitCamera(scene.defaultView(), 45.0f, 64.0f / 48.0f);
    cfg.maxSamples = 5;
    Capture cap;
    ClientSession s(scene, cfg, cap.output());
    // Five passes are rendered, but without an acknowledgement only the first is sent.
    ASSERT_TRUE(eventually([&] { return s.idle(); }));
    ASSERT_EQ(cap.count(), 1u);
    EXPECT_EQ(cap.frame(0)["samples"], 1);
    // The acknowledgement releases the newest frame (5 samples), not the second.
    s.handle(json{{"type", "ack"}, {"frame", cap.frame(0)["id"]}}.dump());
    ASSERT_EQ(cap.count(), 2u);
    EXPECT_EQ(cap.frame(1)["samples"], 5);
    // An acknowledgement of another frame id releases nothing.
    s.handle(json{{"type", "ack"}, {"frame", 12345}}.dump());
    EXPECT_EQ(cap.count(), 2u);
    // A new camera drops what waits for the old one: after the ack only frames of the new camera come.
    CameraFrame c = cfg.home;
    c.fovDeg = 30.0f;
    s.handle(cameraMessage(c).dump());
    ASSERT_TRUE(eventually([&] { return s.idle(); }));
    s.handle(json{{"type", "ack"}, {"frame", cap.frame(1)["id"]}}.dump());
    ASSERT_EQ(cap.count(), 3u);
    EXPECT_EQ(cap.frame(2)["camera"]["fov"], 30.0);
    EXPECT_EQ(cap.frame(2)["samples"], 5);
}

// A camera message that arrives after the tab took a pass's request but before the engine
// took its snapshot makes that pass the new view's first sample, and the tab drops the pass
// as stale: the new view's samples start over, so its frame is sample 1 of maxSamples 1 (it
// was 2: the dropped pass and the next one).
TEST(ClientSession, CameraChangeBeforeThePassStartsCountsNoExtraSample) {
    const engine::Scene scene = bunny();
    ViewerConfig cfg = oneSampleConfig(scene);
    ClientSession* session = nullptr;
    std::atomic<int> passes{0};
    std::atomic<bool> armed{false};
    cfg.beforePass = [&] {
        ++passes;
        if (!armed.exchange(false)) return;
        CameraFrame c = cfg.home;
        c.fovDeg = 30.0f;
        session->handle(cameraMessage(c).dump());
    };
    Capture cap;
    ClientSession s(scene, cfg, cap.output());
    session = &s;
    ASSERT_TRUE(eventually([&] { return s.idle(); }));
    ASSERT_EQ(cap.count(), 1u);
    // Settings restart the view; the pass for them is overtaken by the camera change.
    armed = true;
    s.handle(R"({"type":"settings","mesh":{"integrator":"eyelight"}})");
    ASSERT_TRUE(eventually([&] { return !armed && s.idle(); }));
    s.handle(json{{"type", "ack"}, {"frame", cap.frame(0)["id"]}}.dump());
    ASSERT_EQ(cap.count(), 2u);
    EXPECT_EQ(cap.frame(1)["camera"]["fov"], 30.0);
    EXPECT_EQ(cap.frame(1)["samples"], 1);
    EXPECT_GE(passes.load(), 3);  // the first frame, the overtaken pass, the new view's
}

TEST(ClientSession, BadMessagesChangeNothing) {
    const engine::Scene scene = bunny();
    ViewerConfig cfg = oneSampleConfig(scene);
    Capture cap;
    ClientSession s(scene, cfg, cap.output());
    ASSERT_TRUE(eventually([&] { return s.idle(); }));
    s.handle(R"({"type":"settings","mesh":{"integrator":"direct","maxDepth":0}})");
    s.handle(R"({"type":"settings","mesh":{"material":"gold"}})");
    {
        std::lock_guard l(cap.m);
        ASSERT_EQ(cap.texts.size(), 2u);
        EXPECT_EQ(cap.texts[0]["type"], "error");
        EXPECT_NE(cap.texts[0]["message"].get<std::string>().find("maxDepth"), std::string::npos);
        EXPECT_NE(cap.texts[1]["message"].get<std::string>().find("material"), std::string::npos);
    }
    // No restart happened: the session is still idle with its one frame.
    EXPECT_TRUE(s.idle());
    EXPECT_EQ(cap.count(), 1u);
    const json hello = json::parse(s.hello());
    EXPECT_EQ(hello["settings"]["maxDepth"], 6);
    EXPECT_EQ(hello["settings"]["material"], "default");
}
