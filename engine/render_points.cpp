// Point clouds: preparation (normals, radii), the LoD kd-tree and the integrator table
// (eyelight | direct | ao), with the library's light rig and AO offsets for splats.
#include <chrono>

#include "core/render/ao_integrator.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "core/render/path_integrator.h"
#include "core/render/whitted_integrator.h"
#include "engine/built_scene.h"
#include "engine/renderable.h"
#include "points/point_scene.h"

namespace rtfact::engine {

const std::vector<std::string>& pointIntegrators() {
    static const std::vector<std::string> names{"eyelight", "direct", "ao", "whitted", "path"};
    return names;
}

const std::vector<std::string>& pointAccels() {
    static const std::vector<std::string> names{"kd", "wide"};
    return names;
}

namespace detail {

namespace {

using points::PointScene;

// Two lights: a point light above the camera and a dim directional fill.
LightList pointLightRig(const AABB& b, const CameraFrame& frame) {
    const Vec3f e = b.extent();
    const Vec3f toEye = normalize(frame.eye - frame.at);
    LightList lights;
    lights.push_back(
        PointLight{frame.eye + Vec3f(0, 1, 0) * length(e) + toEye * 0.2f * length(e), Vec3f(2.5f * dot(e, e))});
    lights.push_back(DirectionalLight{{0.3f, -1.0f, -0.4f}, Vec3f(0.5f)});
    return lights;
}

template <class I>
std::unique_ptr<Renderable> make(std::shared_ptr<PointScene> scene, I integ, const PointSettings& s) {
    auto r = std::make_unique<RenderableOf<PointScene, I>>(scene, std::move(integ));
    const float quality = s.lod ? s.lodQuality : 0.0f;
    r->onCamera = [quality](PointScene& sc, const PinholeCamera& cam) { sc.setLoD(cam.cone(), quality); };
    r->stats = [quality](Stats& st, const RenderStats& rst) {
        st.add("lod_nodes_hit", (unsigned long long)rst.counters.lodNodesHit);
        st.add("lod_quality", double(quality));
    };
    return r;
}

}  // namespace

std::shared_ptr<PointScene> buildPointScene(SceneData& d, const PointSettings& s, const CameraFrame& frame,
                                            Stats& stats) {
    requireName(pointAccels(), s.accel, "--accel");
    PointData& pd = d.points;
    const std::string prepareKey = s.normals + "|" + std::to_string(s.radius) + "|" + std::to_string(s.radiusFactor);
    const std::string range =
        s.colorRange ? std::to_string((*s.colorRange)[0]) + "," + std::to_string((*s.colorRange)[1]) : "";
    const std::string buildKey = prepareKey + "|" + std::to_string(int(s.color)) + "|" + s.colorAttribute + "|" +
                                 s.colormap + "|" + range + "|" + std::to_string(s.leafSize) + "|" + s.accel;
    if (pd.buildKey != buildKey) {
        if (pd.sourceReleased)
            throw UsageError("settings",
                             "normals, radii, colour mode and leaf size are fixed once the point cloud "
                             "is released (open with keepSource)");
        if (pd.prepareKey != prepareKey) {
            // Preparing fills the cloud's normals and radii: other options need the file again.
            if (!pd.prepareKey.empty())
                throw UsageError("settings", "normals and radius options are fixed once the cloud is prepared");
            points::PrepareOptions po;
            po.normals = s.normals;
            po.radius = s.radius;
            po.radiusFactor = s.radiusFactor;
            po.viewpoint = frame.eye;
            const auto t0 = std::chrono::steady_clock::now();
            const points::PrepareReport pr = points::preparePointCloud(pd.cloud, po, d.source);
            stats.add("prepare_ms", msSince(t0));
            stats.add("normals", pr.estimatedNormals ? "estimated" : "file");
            stats.add("radii", s.radius > 0 ? "fixed" : pr.estimatedRadii ? "spacing" : "file");
            pd.prepareKey = prepareKey;
        }
        const auto t0 = std::chrono::steady_clock::now();
        auto scene = std::make_shared<PointScene>();
        scene->colorMode = s.color;
        {
            points::ColorOptions co;
            co.mode = s.color;
            co.attribute = s.colorAttribute;
            co.colormap = s.colormap;
            co.range = s.colorRange;
            std::vector<points::Disc> discs = points::makeDiscs(pd.cloud, co, d.source);
            // the discs hold everything rendering needs
            if (!d.keepSource) {
                pd.cloud = points::PointCloud{};
                pd.sourceReleased = true;
            }
            points::LoDKdTreeBuilder b;
            b.maxLeafSize = s.leafSize;
            if (s.accel == "wide") {
                scene->accel = points::PointAccel::Wide;
                scene->wideSplit = points::LoDWideSplit::Median;  // the SAH split builds ~5x slower
            }
            scene->build(std::move(discs), b);
        }
        const double buildMs = msSince(t0);
        stats.add("build_ms", buildMs);
        stats.add("build_points_per_s", buildMs > 0 ? double(scene->discs().size()) / (buildMs * 1e-3) : 0.0);
        stats.add("bytes_per_point", scene->bytesPerPoint());
        stats.add("tree_nodes", (unsigned long long)scene->nodeCount());
        pd.scene = scene;
        pd.buildKey = buildKey;
    }
    return std::static_pointer_cast<PointScene>(pd.scene);
}

std::unique_ptr<Renderable> makePointRenderable(SceneData& d, const PointSettings& s, const CameraFrame& frame,
                                                Stats& stats) {
    requireName(pointIntegrators(), s.integrator, "--integrator");
    auto scene = buildPointScene(d, s, frame, stats);
    if (s.integrator == "eyelight") return make(scene, EyeLightIntegrator{}, s);
    if (s.integrator == "ao") {
        AOIntegrator ao;
        ao.samples = s.aoSamples;
        // Splats overlap their neighbours: start AO rays clear of the local surface.
        ao.offset = 4e-3f;
        ao.minDistance = 4e-3f;
        return make(scene, ao, s);
    }
    // Whitted and path tracing: the core's integrators on the disc scene (front/back from
    // the disc normal), a white Lambert material so the points' colours show.
    PathMaterial white;
    white.albedo = Vec3f(1.0f);
    if (s.integrator == "path") {
        PathIntegrator pt;
        pt.maxDepth = 6;
        pt.materials = {white};
        pt.background = Vec3f(0.9f, 0.95f, 1.0f);  // lit by a bright sky, as meshes without emitters
        return make(scene, pt, s);
    }
    if (s.integrator == "whitted") {
        WhittedIntegrator w;
        w.lights = pointLightRig(scene->bounds(), frame);
        w.maxDepth = 8;
        w.materials = {white};
        auto r = make(scene, w, s);
        r->followsCamera = true;
        return r;
    }
    DirectLightIntegrator integ;
    integ.lights = pointLightRig(scene->bounds(), frame);
    auto r = make(scene, integ, s);
    r->followsCamera = true;
    return r;
}

}  // namespace detail

std::shared_ptr<points::PointScene> builtPoints(const Scene& scene, const Settings& settings, const CameraFrame& frame,
                                                Stats* stats) {
    detail::SceneData& d = *scene.data;
    if (d.kind != SceneKind::Points) throw UsageError("scene", "builtPoints needs a point cloud");
    std::lock_guard lock(d.mutex);
    Stats ignored;
    return detail::buildPointScene(d, settings.points, frame, stats ? *stats : ignored);
}

}  // namespace rtfact::engine
