// ClientSession: one browser tab's view of the shared scene. It owns an engine
// RenderSession and a render thread: camera messages restart the accumulation (and
// cancel the pass in flight); while the camera moves, passes run at the preview scale
// the frame-time controller picks, once per camera; when it is still, passes run at full
// resolution and accumulate up to the sample limit. Frames go out as soon as the page has
// acknowledged the previous one; a newer frame replaces one that is waiting, so the page
// never gets a stale picture. No networking here: the server gives the two send functions.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "apps/view/preview_scale.h"
#include "apps/view/protocol.h"
#include "engine/render_session.h"
#include "engine/scene.h"

namespace rtfact::viewer {

struct ViewerConfig {
    engine::Settings settings;
    engine::FrameOptions frame;  // full resolution, threads, packet
    CameraFrame home;            // the initial camera (--eye/--at/--up or fitted)
    int maxSamples = 64;         // accumulation limit when still
    double frameMs = 40.0;       // preview frame-time target while moving
    int jpegQuality = 85;
    int screenshotSpp = 1;  // samples per pixel of the screenshot PNG (the CLI's --spp)
    // When set, renders each pass in place of the tab's RenderSession and returns the
    // accumulated frame: rank 0 of an MPI run shares the pass with every rank
    // (apps/rtfact/mpi_view.cpp). Called on the tab's render thread; not cancelled.
    struct PassRequest {
        uint64_t view = 0;  // the tab (its accumulation)
        CameraFrame camera;
        engine::Settings settings;
        // The page's settings messages merged (JSON merge patch): applied to the
        // command line's settings, they give `settings` (another process can).
        nlohmann::json settingsPatch;
        int width = 0, height = 0, scale = 1;
    };
    std::function<std::pair<engine::PassResult, engine::Frame>(const PassRequest&)> renderPass;
    std::function<void(uint64_t view)> closeView;  // the tab is gone
    // Tests: called on the render thread after a pass's request is taken and before the
    // pass starts (the window where a message can overtake the pass).
    std::function<void()> beforePass;
};

class ClientSession {
   public:
    struct Output {
        std::function<void(std::string)> text;                        // a JSON text message
        std::function<void(std::string, std::vector<uint8_t>)> pair;  // JSON meta data, then a binary message
    };
    ClientSession(engine::Scene scene, ViewerConfig config, Output out);
    ~ClientSession();
    ClientSession(const ClientSession&) = delete;
    ClientSession& operator=(const ClientSession&) = delete;

    // The first message to the page: the scene, the camera, the settings and the choices.
    std::string hello() const;
    // One text message from the page (any thread); bad ones get an error reply.
    void handle(std::string_view text);
    // Ends the render thread soon (the pass in flight is cancelled); join() waits for it.
    void stop();
    void join();
    bool finished() const { return finished_; }
    // Nothing to render until the page sends something (accumulation complete, or the
    // preview of a moving camera sent); for tests and the benchmark.
    bool idle() const {
        std::lock_guard l(m_);
        return idle_;
    }

   private:
    struct Outgoing {
        std::string meta;
        std::vector<uint8_t> bytes;
    };
    void run();
    void renderOnce(std::unique_lock<std::mutex>& lock);
    void screenshot(std::unique_lock<std::mutex>& lock);
    void deliver(uint64_t id, Outgoing f);
    bool moving(std::chrono::steady_clock::time_point now) const;

    engine::Scene scene_;
    ViewerConfig config_;
    Output out_;

    mutable std::mutex m_;  // guards the fields below
    std::condition_variable cv_;
    std::shared_ptr<engine::RenderSession> session_;
    CameraFrame camera_;
    engine::Settings settings_, goodSettings_;
    nlohmann::json patch_ = nlohmann::json::object(), goodPatch_ = nlohmann::json::object();  // of settings_
    int width_, height_;
    bool stop_ = false, moving_ = false, settingsDirty_ = false, sizeDirty_ = false, screenshotWanted_ = false;
    bool lossless_ = false, idle_ = false;
    int quality_;
    std::chrono::steady_clock::time_point lastMove_;
    uint64_t nextFrame_ = 1, inFlight_ = 0;
    uint64_t generation_ = 0;  // of the view: frames rendered for an older one are dropped
    int scale_ = 1, accumulated_ = 0;
    std::optional<std::pair<uint64_t, Outgoing>> waiting_;
    PreviewScale preview_;

    const uint64_t view_;  // this tab's id for ViewerConfig::renderPass
    std::atomic<bool> finished_{false};
    std::thread thread_;
};

}  // namespace rtfact::viewer
