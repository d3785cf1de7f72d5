#include "apps/view/client_session.h"

#include <tuple>

#include "apps/view/image_encoders.h"
#include "core/util/error.h"
#include "engine/histogram.h"

namespace rtfact::viewer {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {
// A camera message newer than this keeps the view "moving" (the page sends moving: false
// when a drag ends; this covers pages that vanish mid-drag).
constexpr auto kMoveHold = std::chrono::milliseconds(300);
std::atomic<uint64_t> nextView{1};
}  // namespace

ClientSession::ClientSession(engine::Scene scene, ViewerConfig config, Output out)
    : scene_(std::move(scene)),
      config_(std::move(config)),
      out_(std::move(out)),
      camera_(config_.home),
      settings_(config_.settings),
      goodSettings_(config_.settings),
      width_(config_.frame.width),
      height_(config_.frame.height),
      quality_(config_.jpegQuality),
      preview_(config_.frameMs),
      view_(nextView.fetch_add(1)) {
    config_.frame.progress = false;
    session_ = std::make_shared<engine::RenderSession>(scene_, settings_, config_.frame, camera_);
    thread_ = std::thread([this] { run(); });
}

ClientSession::~ClientSession() {
    stop();
    join();
    if (config_.closeView) config_.closeView(view_);
}

void ClientSession::stop() {
    std::lock_guard l(m_);
    stop_ = true;
    session_->cancel();
    cv_.notify_all();
}

void ClientSession::join() {
    if (thread_.joinable()) thread_.join();
}

std::string ClientSession::hello() const {
    std::lock_guard l(m_);
    json info = json::object();
    for (const auto& [k, v] : scene_.info().entries()) info[k] = v;
    const AABB b = scene_.bounds();
    return json{{"type", "hello"},
                {"kind", engine::kindName(scene_.kind())},
                {"source", scene_.source()},
                {"info", info},
                {"bounds", {{b.lo.x, b.lo.y, b.lo.z}, {b.hi.x, b.hi.y, b.hi.z}}},
                {"width", width_},
                {"height", height_},
                {"camera", cameraJson(camera_)},
                {"home", cameraJson(config_.home)},
                {"settings", settingsJson(settings_, scene_.kind())},
                {"choices", choicesJson(scene_.kind())},
                {"maxSamples", config_.maxSamples},
                {"frameMs", config_.frameMs}}
        .dump();
}

void ClientSession::handle(std::string_view text) {
    ClientMessage msg;
    try {
        msg = parseMessage(text);
    } catch (const Error& e) {
        out_.text(errorJson(e.message()).dump());
        return;
    }
    using T = ClientMessage::Type;
    std::unique_lock l(m_);
    // Everything but acks and format changes makes the frames in the making stale.
    auto restart = [&] {
        session_->cancel();  // the pass in flight renders an outdated view
        idle_ = false;
        ++generation_;
        accumulated_ = 0;
        waiting_.reset();
        cv_.notify_all();
    };
    auto setCamera = [&](const CameraFrame& c, bool moving) {
        camera_ = c;
        moving_ = moving;
        lastMove_ = Clock::now();
        session_->setCamera(c);
        restart();
    };
    switch (msg.type) {
        case T::Camera:
            setCamera(msg.camera, msg.moving);
            break;
        case T::Ack:
            if (msg.frame == inFlight_) {
                inFlight_ = 0;
                if (waiting_) {
                    auto [id, f] = std::move(*waiting_);
                    waiting_.reset();
                    inFlight_ = id;
                    out_.pair(std::move(f.meta), std::move(f.bytes));
                }
            }
            break;
        case T::Resize:
            width_ = msg.width;
            height_ = msg.height;
            sizeDirty_ = true;
            restart();
            break;
        case T::Settings:
            try {
                applySettings(msg.settings, scene_.kind(), settings_);
            } catch (const Error& e) {
                l.unlock();
                out_.text(errorJson(e.message()).dump());
                return;
            }
            patch_.merge_patch(msg.settings);
            settingsDirty_ = true;
            restart();
            break;
        case T::Fit:
        case T::Reset: {
            const CameraFrame c =
                msg.type == T::Reset
                    ? config_.home
                    : engine::fitCamera(scene_.defaultView(settings_), camera_.fovDeg, float(width_) / float(height_));
            setCamera(c, false);
            json j = cameraJson(c);
            j["type"] = "camera";
            out_.text(j.dump());
            break;
        }
        case T::Screenshot:
            screenshotWanted_ = true;
            idle_ = false;
            cv_.notify_all();
            break;
        case T::Format:
            lossless_ = msg.lossless;
            quality_ = msg.quality;
            break;
    }
}

bool ClientSession::moving(Clock::time_point now) const { return moving_ && now - lastMove_ < kMoveHold; }

void ClientSession::deliver(uint64_t id, Outgoing f) {
    if (inFlight_ == 0) {
        inFlight_ = id;
        out_.pair(std::move(f.meta), std::move(f.bytes));
    } else {
        waiting_ = std::make_pair(id, std::move(f));  // replaces an older waiting frame
    }
}

void ClientSession::run() {
    std::unique_lock lock(m_);
    bool transferDirty = scene_.kind() == engine::SceneKind::Volume;
    while (!stop_) {
        if (screenshotWanted_) {
            screenshot(lock);
            continue;
        }
        if (sizeDirty_) {
            engine::FrameOptions fo = config_.frame;
            fo.width = width_;
            fo.height = height_;
            session_ = std::make_shared<engine::RenderSession>(scene_, settings_, fo, camera_);
            sizeDirty_ = false;
        }
        if (settingsDirty_) {
            session_->setSettings(settings_);
            settingsDirty_ = false;
            preview_.reset();
            transferDirty = scene_.kind() == engine::SceneKind::Volume;
        }
        if (transferDirty) {
            // The histogram and the TF in use, for the page's editor (the default TF
            // depends on the mode).
            transferDirty = false;
            const engine::Settings s = settings_;
            lock.unlock();
            json j = transferJson(engine::volumeTransferInfo(scene_, s));
            j["type"] = "transfer";
            out_.text(j.dump());
            lock.lock();
            continue;
        }
        const Clock::time_point now = Clock::now();
        const bool mv = moving(now);
        const int scale = mv ? preview_.scaleFor(double(width_) * double(height_)) : 1;
        if (scale != scale_) {
            session_->setScale(scale);
            scale_ = scale;
            accumulated_ = 0;
            ++generation_;
        }
        // Moving: one preview per camera; still: accumulate up to the limit.
        const bool work = scale > 1 ? accumulated_ == 0 : accumulated_ < config_.maxSamples;
        if (!work) {
            idle_ = !mv && !screenshotWanted_;
            if (mv)
                cv_.wait_until(lock, lastMove_ + kMoveHold);
            else
                cv_.wait(lock);
            idle_ = false;
            continue;
        }
        renderOnce(lock);
    }
    finished_ = true;
}

void ClientSession::renderOnce(std::unique_lock<std::mutex>& lock) {
    const std::shared_ptr<engine::RenderSession> session = session_;
    const uint64_t generation = generation_;
    const bool mv = moving_;
    const ViewerConfig::PassRequest request{view_, camera_, settings_, patch_, width_, height_, scale_};
    lock.unlock();
    if (config_.beforePass) config_.beforePass();
    engine::PassResult r;
    engine::Frame frame;
    std::string error;
    try {
        if (config_.renderPass) {
            std::tie(r, frame) = config_.renderPass(request);
        } else {
            r = session->renderPass();
            if (r.status == engine::PassResult::Status::Done) frame = session->frame();
        }
    } catch (const Error& e) {
        error = e.message();
    }
    Outgoing out;
    bool lossless = false;
    if (error.empty() && r.status == engine::PassResult::Status::Done) {
        {
            std::lock_guard l(m_);
            lossless = lossless_;
        }
        try {
            out.bytes = lossless ? encodePng(frame) : encodeJpeg(frame, quality_);
        } catch (const Error& e) {
            error = e.message();
        }
    }
    lock.lock();
    if (!error.empty()) {
        // Settings the engine refused: back to the last good ones.
        settings_ = goodSettings_;
        patch_ = goodPatch_;
        settingsDirty_ = true;
        ++generation_;
        accumulated_ = 0;
        out_.text(errorJson(error).dump());
        return;
    }
    if (r.status != engine::PassResult::Status::Done) return;
    if (generation != generation_) {
        // Stale. A camera change that reached the engine before the pass took its snapshot
        // made this pass the new view's first sample, which the next pass would then add to
        // (one sample past maxSamples, and the frame of sample 1 never sent): start that
        // view's samples over.
        if (session == session_) session->restart();
        return;
    }
    goodSettings_ = settings_;
    goodPatch_ = patch_;
    accumulated_ = r.samples;
    preview_.observe(r.render.ms, double(frame.width) * double(frame.height));
    const uint64_t id = nextFrame_++;
    out.meta = json{{"type", "frame"},
                    {"id", id},
                    {"width", frame.width},
                    {"height", frame.height},
                    {"fullWidth", width_},
                    {"fullHeight", height_},
                    {"scale", scale_},
                    {"samples", r.samples},
                    {"moving", mv},
                    {"ms", r.render.ms},
                    {"mrays", r.render.ms > 0 ? double(r.render.rays) / (r.render.ms * 1e3) : 0.0},
                    {"format", lossless ? "png" : "jpeg"},
                    {"camera", cameraJson(camera_)}}
                   .dump();
    deliver(id, std::move(out));
}

void ClientSession::screenshot(std::unique_lock<std::mutex>& lock) {
    screenshotWanted_ = false;
    const engine::Settings s = settings_;
    const CameraFrame c = camera_;
    engine::FrameOptions fo = config_.frame;
    fo.width = width_;
    fo.height = height_;
    lock.unlock();
    std::string error;
    std::vector<uint8_t> png;
    try {
        // The image `rtfact points|volume|mesh --spp N` writes for this view.
        engine::Stats stats;
        png = encodePng(engine::renderToImage(scene_, s, fo, c, config_.screenshotSpp, stats));
    } catch (const Error& e) {
        error = e.message();
    }
    if (error.empty())
        out_.pair(json{{"type", "screenshot"}, {"width", fo.width}, {"height", fo.height}}.dump(), std::move(png));
    else
        out_.text(errorJson(error).dump());
    lock.lock();
}

}  // namespace rtfact::viewer
