// engine::RenderSession: progressive rendering of a scene. It holds the camera, the
// settings and the accumulation buffer; renderPass() adds one sample per pixel at full
// or reduced resolution. A camera, settings or scale change restarts the accumulation
// and cancels the pass in flight. Setters, cancel() and the accessors may be called
// from any thread while another renders; passes themselves run one at a time (the
// callbacks run inside a pass and must not start another).
#pragma once
#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "core/render/framebuffer.h"
#include "core/render/pinhole_camera.h"
#include "core/render/tile_scheduler.h"
#include "engine/scene.h"

namespace rtfact::engine {

namespace detail {
class Renderable;
}

struct FrameOptions {
    int width = 1024, height = 1024;
    int packet = 0;         // rays per packet; 0: the kind's default (defaultPacketSize)
    int threads = 0;        // 0: all cores
    bool progress = false;  // progress bar on stderr
    // Named in the error when the framebuffer does not fit in memory (e.g. the output file).
    std::string target = "render";
    // Renders only the tiles this source hands out (RenderOptions::nextTile; the other
    // pixels stay empty): the MPI image-parallel mode's ranks share one image this way.
    std::function<int()> nextTile;
    // Frame::depth is filled: the nearest hit per pixel (+inf where nothing was hit), so that
    // parts rendered apart can be depth-composited (docs/mpi.md).
    bool depth = false;
};

// Rays per packet that measured best for each kind (64 for all: render_session.cpp).
int defaultPacketSize(SceneKind kind);

// The default camera for a view: the whole focus box in sight.
CameraFrame fitCamera(const DefaultView& view, float fovDeg, float aspect);

struct PassResult {
    enum class Status { Done, Cancelled, Restarted } status = Status::Done;
    int samples = 0;     // samples per pixel accumulated after the pass
    RenderStats render;  // of this pass
};

// A resolved image: RGBA floats, averaged over `samples`.
struct Frame {
    int width = 0, height = 0, samples = 0;
    std::vector<float> rgba;
    std::vector<float> depth;  // with FrameOptions::depth: width x height, the minimum over the samples
};

// Eye-dome lighting strength a render of `scene` with `settings` applies (0: none): point
// clouds only; --edl, else on for clouds whose file had no normals.
float eyeDomeStrength(const Scene& scene, const Settings& settings);
// Applies eye-dome lighting to `frame` from its depth (FrameOptions::depth), as a render
// does: for images composited from parts rendered without it (Settings' points.edl = 0).
void applyEyeDomeLighting(Frame& frame, float strength);

class RenderSession {
   public:
    RenderSession(Scene scene, Settings settings, FrameOptions frame, CameraFrame camera);
    ~RenderSession();
    RenderSession(const RenderSession&) = delete;
    RenderSession& operator=(const RenderSession&) = delete;

    void setCamera(const CameraFrame& camera);
    void setSettings(const Settings& settings);
    // Renders at 1/scale of the full resolution in each axis (1: full).
    void setScale(int scale);
    // Stops the pass in flight within one tile per render thread (it returns Cancelled).
    void cancel();
    // Starts the accumulation over with the same view (and cancels the pass in flight):
    // the next pass is sample 1 again.
    void restart();
    // Called after every completed pass with the accumulated image (on the rendering thread).
    void onFrame(std::function<void(const Frame&)> f);
    // Called after every tile with (tiles done, tiles in the pass) (on worker threads).
    void onProgress(std::function<void(uint64_t, uint64_t)> f);

    // One sample pass; renderSamples(n): n samples in one pass (a one-shot n-spp render).
    PassResult renderPass() { return renderSamples(1); }
    PassResult renderSamples(int n);

    Frame frame() const;
    int samples() const;
    CameraFrame camera() const;
    int width() const;
    int height() const;
    // Preparation and build statistics of the current settings, then the render
    // counters of the passes since the last restart.
    Stats stats() const;
    Stats buildStats() const;
    // Waits for the pass in flight.
    Stats counters() const;

   private:
    // A new generation (the accumulation starts over at the next pass) and the pass in
    // flight cancelled; state_ held.
    void restartLocked();
    struct Snapshot;
    Scene scene_;
    FrameOptions opts_;
    mutable std::mutex state_;  // the fields below
    CameraFrame camera_;
    Settings settings_;
    int scale_ = 1;
    uint64_t generation_ = 0, settingsGeneration_ = 0;
    std::function<void(const Frame&)> frameCb_;
    std::function<void(uint64_t, uint64_t)> progressCb_;
    // Accumulation: the first pass renders straight into first_; later passes into
    // first_ (cleared) and are summed into sum_.
    std::unique_ptr<RGBAFramebuffer> first_;
    std::vector<float> sum_;
    int samples_ = 0;
    uint64_t accumGeneration_ = ~uint64_t(0);
    RenderStats lastRender_;
    Stats buildStats_;

    mutable std::mutex render_;  // one pass at a time; the fields below
    std::atomic<bool> cancel_{false};
    std::unique_ptr<detail::Renderable> renderable_;
    uint64_t renderableGeneration_ = ~uint64_t(0), renderableCamera_ = ~uint64_t(0);
};

// One-shot: renders `spp` samples in one pass and returns the image; `stats` receives
// the build statistics, then render_ms rays mrays_per_s threads packet spp width height,
// then the domain's counters.
Frame renderToImage(const Scene& scene, const Settings& settings, const FrameOptions& frame, const CameraFrame& camera,
                    int spp, Stats& stats);

}  // namespace rtfact::engine
