#include "engine/render_session.h"

#include <algorithm>

#include "core/render/eye_dome_lighting.h"
#include "core/util/memory_budget.h"
#include "engine/renderable.h"

namespace rtfact::engine {

namespace detail {

void requireName(const std::vector<std::string>& table, const std::string& name, const std::string& option) {
    if (std::find(table.begin(), table.end(), name) != table.end()) return;
    std::string all;
    for (const std::string& n : table) all += (all.empty() ? "" : ", ") + n;
    throw UsageError(option, "'" + name + "' is not one of " + all);
}

namespace {

// The kind's render unit makes the renderable.
std::unique_ptr<Renderable> makeRenderable(SceneData& d, const Settings& s, const CameraFrame& camera, Stats& stats) {
    switch (d.kind) {
        case SceneKind::Points:
            return makePointRenderable(d, s.points, camera, stats);
        case SceneKind::Mesh:
            return makeMeshRenderable(d, s.mesh, camera, stats);
        case SceneKind::Volume:
            return makeVolumeRenderable(d, s.volume, stats);
        default:
            return makeSpheresRenderable(d, s.spheres, stats);
    }
}

}  // namespace

// Eye-dome lighting strength of these settings (0: none): point clouds only; by default
// on for clouds whose file had no normals (estimated normals shade them poorly).
float edlStrength(const SceneData& d, const Settings& s) {
    if (d.kind != SceneKind::Points) return 0.0f;
    if (s.points.edl) return *s.points.edl;
    return d.info.get("normals") == "none" ? 1.0f : 0.0f;
}

}  // namespace detail

float eyeDomeStrength(const Scene& scene, const Settings& settings) {
    if (!scene.data) throw UsageError("scene", "no scene");
    return detail::edlStrength(*scene.data, settings);
}

void applyEyeDomeLighting(Frame& frame, float strength) {
    if (strength <= 0) return;
    if (frame.depth.size() != size_t(frame.width) * size_t(frame.height) || frame.rgba.size() != frame.depth.size() * 4)
        throw UsageError("frame", "eye-dome lighting needs the frame's depth (FrameOptions::depth)");
    ::rtfact::applyEyeDomeLighting(frame.rgba, frame.depth, frame.width, frame.height, strength);
}

// 64 rays (8 x 8 pixels) for every kind. Point clouds had 16 since the first LoD kd-tree;
// since the packet traversals share their top levels and trace in 4 x 4 tiles, 64 renders
// the scans 20-40% faster at one thread (kd-tree, eyelight and AO, both ISAs; the wide BVH
// a few percent), with the same images (docs/benchmarks.md, session 35).
int defaultPacketSize(SceneKind) { return 64; }

CameraFrame fitCamera(const DefaultView& view, float fovDeg, float aspect) {
    return ::rtfact::fitCamera(view.focus, fovDeg, aspect, view.viewDir, view.up);
}

RenderSession::RenderSession(Scene scene, Settings settings, FrameOptions frame, CameraFrame camera)
    : scene_(std::move(scene)), opts_(std::move(frame)), camera_(camera), settings_(std::move(settings)) {
    if (!scene_.data) throw UsageError("scene", "no scene");
    if (opts_.width < 1 || opts_.height < 1) throw UsageError("--size", "width and height must be at least 1");
}

RenderSession::~RenderSession() = default;

void RenderSession::restartLocked() {
    ++generation_;
    cancel_.store(true);
}

void RenderSession::setCamera(const CameraFrame& camera) {
    std::lock_guard l(state_);
    camera_ = camera;
    restartLocked();
}

void RenderSession::setSettings(const Settings& settings) {
    std::lock_guard l(state_);
    settings_ = settings;
    ++settingsGeneration_;
    restartLocked();
}

void RenderSession::setScale(int scale) {
    if (scale < 1) throw UsageError("scale", "must be at least 1");
    std::lock_guard l(state_);
    if (scale == scale_) return;
    scale_ = scale;
    restartLocked();
}

void RenderSession::cancel() { cancel_.store(true); }

void RenderSession::restart() {
    std::lock_guard l(state_);
    restartLocked();
}

void RenderSession::onFrame(std::function<void(const Frame&)> f) {
    std::lock_guard l(state_);
    frameCb_ = std::move(f);
}

void RenderSession::onProgress(std::function<void(uint64_t, uint64_t)> f) {
    std::lock_guard l(state_);
    progressCb_ = std::move(f);
}

PassResult RenderSession::renderSamples(int n) {
    if (n < 1) throw UsageError("--spp", "must be at least 1");
    std::lock_guard renderLock(render_);
    CameraFrame camera;
    Settings settings;
    uint64_t generation = 0, settingsGeneration = 0;
    int scale = 1;
    RenderOptions ro;
    {
        std::lock_guard l(state_);
        // Cleared with the snapshot: a change after this point cancels the pass.
        cancel_.store(false);
        camera = camera_;
        settings = settings_;
        generation = generation_;
        settingsGeneration = settingsGeneration_;
        scale = scale_;
        ro.onTile = progressCb_;
    }
    detail::SceneData& data = *scene_.data;
    std::lock_guard sceneLock(data.mutex);
    if (!renderable_ || renderableGeneration_ != settingsGeneration) {
        renderable_.reset();
        Stats s;
        renderable_ = detail::makeRenderable(data, settings, camera, s);
        renderableGeneration_ = settingsGeneration;
        renderableCamera_ = generation;
        std::lock_guard l(state_);
        buildStats_ = std::move(s);
    } else if (renderable_->followsCamera && renderableCamera_ != generation) {
        // same settings, new camera: nothing is rebuilt, the statistics stay those of the build
        renderable_.reset();
        Stats ignored;
        renderable_ = detail::makeRenderable(data, settings, camera, ignored);
        renderableCamera_ = generation;
    }
    const int w = std::max(1, opts_.width / scale), h = std::max(1, opts_.height / scale);
    {
        std::lock_guard l(state_);
        const bool edl = detail::edlStrength(data, settings) > 0 || opts_.depth;
        const bool resize = !first_ || first_->width() != w || first_->height() != h || first_->hasDepth() != edl;
        if (resize) {
            first_.reset();
            sum_.clear();
            // Accumulation buffer, resolved copy and 8-bit output.
            checkMemory(opts_.target, uint64_t(w) * uint64_t(h) * (edl ? 44u : 36u),
                        "a " + std::to_string(w) + "x" + std::to_string(h) + " framebuffer", "use a smaller --size");
            first_ = std::make_unique<RGBAFramebuffer>(w, h, edl);
        }
        const bool restart = accumGeneration_ != generation || resize;
        if (restart) {
            sum_.clear();
            samples_ = 0;
            accumGeneration_ = generation;
        } else if (samples_ > 0 && sum_.empty()) {
            // The first pass moves to the sum; first_ becomes the pass buffer.
            sum_.assign(first_->rawRGBA(), first_->rawRGBA() + size_t(w) * size_t(h) * 4);
        }
        // Each tile's first sample replaces its pixels (RenderOptions::clear); where only
        // some tiles are rendered here (nextTile) the others must hold zeros, which a new
        // buffer does. The depth (for EDL) stays the minimum over the accumulated passes, as
        // in one pass of all their samples: it is cleared until a pass of this camera has
        // completed (a cancelled first pass leaves the old camera's depth in the tiles it did
        // not reach).
        using Clear = RenderOptions::Clear;
        const Clear clear = samples_ == 0 ? Clear::ColorAndDepth : Clear::Color;
        ro.clear = clear;
        if (opts_.nextTile && !resize) first_->clear(Region{0, 0, w, h}, clear == Clear::ColorAndDepth);
        ro.firstSample = samples_;
    }
    ro.threads = opts_.threads;
    ro.spp = n;
    ro.progress = opts_.progress;
    ro.cancel = &cancel_;
    ro.nextTile = opts_.nextTile;
    const int packet = opts_.packet > 0 ? opts_.packet : defaultPacketSize(data.kind);
    PassResult res;
    res.render = renderable_->render(camera, *first_, ro, packet);
    Frame frame;
    std::function<void(const Frame&)> cb;
    {
        std::lock_guard l(state_);
        if (generation_ != generation) {
            res.status = PassResult::Status::Restarted;
            return res;
        }
        if (res.render.cancelled) {
            res.status = PassResult::Status::Cancelled;
            res.samples = samples_;
            return res;
        }
        if (samples_ > 0) {
            const float* p = first_->rawRGBA();
            for (size_t i = 0; i < sum_.size(); ++i) sum_[i] += p[i];
        }
        samples_ += n;
        res.samples = samples_;
        lastRender_ = res.render;
        cb = frameCb_;
    }
    if (cb) {
        frame = this->frame();
        cb(frame);
    }
    return res;
}

Frame RenderSession::frame() const {
    std::lock_guard l(state_);
    Frame f;
    if (!first_) return f;
    f.width = first_->width();
    f.height = first_->height();
    f.samples = samples_;
    if (samples_ == 0) {
        f.rgba.assign(size_t(f.width) * size_t(f.height) * 4, 0.0f);
    } else if (sum_.empty()) {
        f.rgba = first_->resolved(samples_);
    } else {
        // as RGBAFramebuffer::resolved: the sum times the reciprocal of the count
        const float inv = 1.0f / float(samples_);
        f.rgba.resize(sum_.size());
        for (size_t i = 0; i < sum_.size(); ++i) f.rgba[i] = sum_[i] * inv;
    }
    if (opts_.depth) f.depth = first_->depth();
    // The depth of the last pass shades the averaged colours.
    const float edl = detail::edlStrength(*scene_.data, settings_);
    if (samples_ > 0 && first_->hasDepth() && edl > 0)
        ::rtfact::applyEyeDomeLighting(f.rgba, first_->depth(), f.width, f.height, edl);
    return f;
}

int RenderSession::samples() const {
    std::lock_guard l(state_);
    return samples_;
}

CameraFrame RenderSession::camera() const {
    std::lock_guard l(state_);
    return camera_;
}

int RenderSession::width() const {
    std::lock_guard l(state_);
    return std::max(1, opts_.width / scale_);
}

int RenderSession::height() const {
    std::lock_guard l(state_);
    return std::max(1, opts_.height / scale_);
}

Stats RenderSession::buildStats() const {
    std::lock_guard l(state_);
    return buildStats_;
}

Stats RenderSession::counters() const {
    std::lock_guard renderLock(render_);
    std::lock_guard l(state_);
    Stats s;
    if (renderable_) renderable_->addRenderStats(s, lastRender_);
    return s;
}

Stats RenderSession::stats() const {
    Stats s = buildStats();
    s.append(counters());
    return s;
}

Frame renderToImage(const Scene& scene, const Settings& settings, const FrameOptions& frame, const CameraFrame& camera,
                    int spp, Stats& stats) {
    RenderSession session(scene, settings, frame, camera);
    const RenderStats rs = session.renderSamples(spp).render;
    stats.append(session.buildStats());
    stats.add("render_ms", rs.ms);
    stats.add("rays", (unsigned long long)rs.rays);
    stats.add("mrays_per_s", rs.ms > 0 ? double(rs.rays) / (rs.ms * 1000.0) : 0.0);
    stats.add("threads", rs.threads);
    stats.add("packet", frame.packet > 0 ? frame.packet : defaultPacketSize(scene.kind()));
    stats.add("spp", spp);
    stats.add("width", frame.width);
    stats.add("height", frame.height);
    stats.append(session.counters());
    return session.frame();
}

}  // namespace rtfact::engine
