// Inside the engine: a scene prepared and built for one set of settings, with its
// integrator chosen, ready to render passes at any packet size. Each domain's render
// unit (render_points.cpp, render_mesh.cpp, render_volume.cpp, render_spheres.cpp) holds
// its name -> integrator table and its renderImage instantiations.
#pragma once
#include <functional>
#include <memory>
#include <string>

#include "core/render/framebuffer.h"
#include "core/render/jittered_sampler.h"
#include "core/render/packet_dispatch.h"
#include "core/render/pinhole_camera.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/tile_scheduler.h"
#include "engine/scene_data.h"
#include "engine/usage_error.h"

namespace rtfact::engine::detail {

class Renderable {
   public:
    virtual ~Renderable() = default;
    // Renders opt.spp samples from opt.firstSample on, accumulating into fb.
    virtual RenderStats render(const CameraFrame& frame, RGBAFramebuffer& fb, const RenderOptions& opt, int packet) = 0;
    // Statistics of the renders so far (counters such as LoD hits or volume samples).
    virtual void addRenderStats(Stats&, const RenderStats&) const {}
    // Camera-relative defaults (a key light placed from the camera): the session makes
    // the renderable again for a new camera (the built structures are kept).
    bool followsCamera = false;
};

// Scene and integrator, and what to do per camera and after rendering.
template <class Scene, class Integ>
requires Integrator<Integ, Scene>
class RenderableOf final : public Renderable {
   public:
    RenderableOf(std::shared_ptr<Scene> scene, Integ integrator)
        : scene_(std::move(scene)), integrator_(std::move(integrator)) {}
    std::function<void(Scene&, const PinholeCamera&)> onCamera;
    std::function<void(Stats&, const RenderStats&)> stats;

    RenderStats render(const CameraFrame& frame, RGBAFramebuffer& fb, const RenderOptions& opt, int packet) override {
        const PinholeCamera cam(frame, fb.width(), fb.height());
        if (onCamera) onCamera(*scene_, cam);
        const RayTracingRenderer<JitteredSampler, Integ> renderer{{}, integrator_};
        const Scene& scene = *scene_;
        RenderStats rs;
        if (!dispatchPacketSize(packet, [&]<int N>() { rs = renderImage<N>(renderer, scene, cam, fb, opt); }))
            throw UsageError("--packet", "must be one of " + supportedPacketSizes());
        return rs;
    }
    void addRenderStats(Stats& s, const RenderStats& rs) const override {
        if (stats) stats(s, rs);
    }

   private:
    std::shared_ptr<Scene> scene_;
    Integ integrator_;
};

// Throws UsageError(option, ...) unless `name` is in `table`.
void requireName(const std::vector<std::string>& table, const std::string& name, const std::string& option);

// Prepares and builds `data` for `settings` (adding prepare/build statistics to `stats`),
// for a camera `frame` (points orient estimated normals towards its eye).
std::unique_ptr<Renderable> makePointRenderable(SceneData& data, const PointSettings& s, const CameraFrame& frame,
                                                Stats& stats);
std::unique_ptr<Renderable> makeMeshRenderable(SceneData& data, const MeshSettings& s, const CameraFrame& frame,
                                               Stats& stats);
std::unique_ptr<Renderable> makeVolumeRenderable(SceneData& data, const VolumeSettings& s, Stats& stats);
std::unique_ptr<Renderable> makeSpheresRenderable(SceneData& data, const SpheresSettings& s, Stats& stats);

}  // namespace rtfact::engine::detail
