// Triangle meshes: the BVH or kd-tree (plus the wide BVH for incoherent rays), the
// material override, the library's light rig, and the integrator table (eyelight |
// direct | whitted | ao | path, with AO and bounce rays in packets or wide single rays).
#include <algorithm>
#include <chrono>

#include "core/render/ao_integrator.h"
#include "core/render/direct_light_integrator.h"
#include "core/render/eyelight_integrator.h"
#include "engine/built_scene.h"
#include "engine/renderable.h"
#include "surfaces/mesh_scene.h"
#include "surfaces/path_integrator.h"
#include "surfaces/whitted_integrator.h"

namespace rtfact::engine {

using namespace rtfact::surfaces;

const std::vector<std::string>& meshIntegrators() {
    static const std::vector<std::string> names{"eyelight", "direct", "whitted", "ao", "path"};
    return names;
}

MeshMaterial lambertMaterial(std::optional<Vec3f> kd) {
    MeshMaterial m;
    m.name = "lambert";
    if (kd) m.kd = *kd;
    return m;
}

MeshMaterial mirrorMaterial(std::optional<Vec3f> ks) {
    MeshMaterial m;
    m.name = "mirror";
    m.illum = 3;
    m.kd = Vec3f(0.0f);
    m.ks = ks.value_or(Vec3f(0.95f));
    return m;
}

MeshMaterial glassMaterial(float ior) {
    if (!(ior >= 1.0f && ior <= 4.0f)) throw UsageError("--material", "glass IOR must be in [1, 4]");
    MeshMaterial m;
    m.name = "glass";
    m.illum = 7;
    m.dissolve = 0.0f;
    m.kd = Vec3f(1.0f);
    m.ior = ior;
    return m;
}

namespace detail {

namespace {

// Point lights are scaled so that the scene centre receives an irradiance of 0.85
// (white surfaces facing the light stay below clipping).
PointLight scaledPointLight(Vec3f p, const AABB& box) {
    const Vec3f d = p - box.center();
    return PointLight{p, Vec3f(0.85f * 3.14159265f * std::max(dot(d, d), 1e-12f))};
}

LightList meshLights(const std::vector<LightSpec>& specs, const AABB& box, const CameraFrame& frame) {
    LightList lights;
    for (const LightSpec& l : specs) {
        if (l.kind == LightSpec::Kind::Point) {
            lights.push_back(scaledPointLight(l.v, box));
        } else {
            if (length(l.v) == 0.0f) throw UsageError("--light", "direction must not be zero");
            lights.push_back(DirectionalLight{normalize(l.v), Vec3f(0.85f * 3.14159265f)});
        }
    }
    if (lights.empty()) {
        // Default: a key light above and to the left of the camera.
        const Vec3f e = box.extent();
        const float r = std::max(length(e), 1e-6f);
        const Vec3f p = frame.eye + normalize(frame.up) * (0.8f * r) -
                        normalize(cross(frame.at - frame.eye, frame.up)) * (0.6f * r);
        lights.push_back(scaledPointLight(p, box));
    }
    return lights;
}

std::string materialKey(const std::optional<MeshMaterial>& m) {
    if (!m) return "";
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s|%d|%g,%g,%g|%g,%g,%g|%g|%g", m->name.c_str(), m->illum, m->kd.x, m->kd.y,
                  m->kd.z, m->ks.x, m->ks.y, m->ks.z, m->ior, m->dissolve);
    return buf;
}

template <class Scene, class I>
std::unique_ptr<Renderable> make(std::shared_ptr<Scene> scene, I integ) {
    return std::make_unique<RenderableOf<Scene, I>>(std::move(scene), std::move(integ));
}

template <class Secondary, class Scene>
std::unique_ptr<Renderable> makeIncoherent(std::shared_ptr<Scene> scene, const MeshSettings& s, const Mesh& mesh) {
    if (s.integrator == "path") {
        PathIntegratorT<Secondary> pt;
        pt.maxDepth = s.maxDepth;
        pt.materials = PathIntegrator::fromMesh(mesh);
        // Without emitters (MTL Ke) the scene is lit by a bright sky.
        const bool emitters = std::any_of(pt.materials.begin(), pt.materials.end(),
                                          [](const PathMaterial& m) { return maxComponent(m.emission) > 0.0f; });
        if (!emitters) pt.background = Vec3f(0.9f, 0.95f, 1.0f);
        return make(std::move(scene), pt);
    }
    AOIntegratorT<Secondary> ao;
    ao.samples = s.aoSamples;
    return make(std::move(scene), ao);
}

template <class Structure>
std::unique_ptr<Renderable> makeMesh(SceneData& d, const MeshSettings& s, const CameraFrame& frame, Stats& stats) {
    MeshData& md = d.mesh;
    const bool incoherent = s.integrator == "path" || s.integrator == "ao";
    // auto: wide single rays for AO and path bounces (the directly built wide BVH beats
    // packets on both, with the same hits; docs/cli.md).
    const std::string secondary = s.secondary != "auto" ? s.secondary : "wide";
    // The SAH BVH scene is the wide BVH alone (its packets serve coherent rays; built in
    // about 0.7x Embree's time), except where AO / path bounces are asked to travel as
    // packets: the binary packet BVH then serves every ray.
    const bool wide = !(incoherent && secondary == "packet");
    const std::string key = s.bvh + "|" + (wide ? "wide" : "") + "|" + materialKey(s.material);
    if (md.buildKey != key) {
        if (!md.mesh) throw UsageError("settings", "the BVH and material are fixed once the mesh is released");
        std::shared_ptr<Mesh> mesh = md.mesh;
        if (s.material) {
            // Replaces every material: on a copy when the loaded mesh is kept.
            if (d.keepSource) mesh = std::make_shared<Mesh>(*md.mesh);
            mesh->materials = {*s.material};
            mesh->materialIds.assign(mesh->triangles(), 0);
            mesh->colors.clear();
        }
        const auto t0 = std::chrono::steady_clock::now();
        auto scene = std::make_shared<MeshScene<Structure>>();
        scene->mesh = mesh;
        scene->buildWide = wide;
        scene->build();
        stats.add("build_ms", msSince(t0));
        stats.add("triangles", (unsigned long long)mesh->triangles());
        stats.add("bvh_bytes", (unsigned long long)scene->memoryBytes());
        md.scene = scene;
        md.rendered = mesh;
        md.buildKey = key;
        if (!d.keepSource) md.mesh.reset();
    }
    auto scene = std::static_pointer_cast<MeshScene<Structure>>(md.scene);
    const Mesh& mesh = *md.rendered;
    if (s.integrator == "eyelight") return make(scene, EyeLightIntegrator{});
    if (incoherent) {
        stats.add("secondary", secondary);
        if (wide) return makeIncoherent<WideSecondaryRays>(scene, s, mesh);
        return makeIncoherent<PacketSecondaryRays>(scene, s, mesh);
    }
    const LightList lights = meshLights(s.lights, scene->bounds(), frame);
    std::unique_ptr<Renderable> r;
    if (s.integrator == "whitted") {
        WhittedIntegrator w;
        w.lights = lights;
        w.maxDepth = s.maxDepth;
        w.materials = PathIntegrator::fromMesh(mesh);
        r = make(scene, w);
    } else {
        DirectLightIntegrator integ;
        integ.lights = lights;
        r = make(scene, integ);
    }
    r->followsCamera = s.lights.empty();  // the default key light is placed from the camera
    return r;
}

}  // namespace

std::unique_ptr<Renderable> makeMeshRenderable(SceneData& d, const MeshSettings& s, const CameraFrame& frame,
                                               Stats& stats) {
    requireName(meshIntegrators(), s.integrator, "--integrator");
    requireName({"sah", "kdtree"}, s.bvh, "--bvh");
    requireName({"auto", "wide", "packet"}, s.secondary, "--secondary");
    if (s.bvh == "kdtree") return makeMesh<KdTree<Triangle>>(d, s, frame, stats);
    return makeMesh<BVH<Triangle>>(d, s, frame, stats);
}

}  // namespace detail

std::shared_ptr<const Mesh> loadedMesh(const Scene& scene) {
    detail::SceneData& d = *scene.data;
    if (d.kind != SceneKind::Mesh) throw UsageError("scene", "loadedMesh needs a mesh");
    std::lock_guard lock(d.mutex);
    if (!d.mesh.mesh) throw UsageError("scene", "the mesh was released after the build (open with keepSource)");
    return d.mesh.mesh;
}
}  // namespace rtfact::engine
