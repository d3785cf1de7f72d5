// Inside an engine::Scene (engine sources only): the loaded data of its kind and what
// has been prepared and built from it, with the settings key it was built for.
#pragma once
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/geometry/sphere_scene.h"
#include "engine/scene.h"
#include "points/point_cloud.h"
#include "surfaces/mesh.h"
#include "volume/brick_volume.h"
#include "volume/gradient_bricks.h"

namespace rtfact::engine::detail {

struct PointData {
    points::PointCloud cloud;  // released after the build unless keepSource
    bool sourceReleased = false;
    std::string prepareKey;       // preparation done for (empty: not prepared)
    std::string buildKey;         // scene built for
    std::shared_ptr<void> scene;  // points::PointScene
};

struct MeshData {
    std::shared_ptr<surfaces::Mesh> mesh;  // as loaded; released after the build unless keepSource
    std::string buildKey;
    std::shared_ptr<void> scene;                     // MeshScene<BVH<Triangle>> or MeshScene<KdTree<Triangle>>
    std::shared_ptr<const surfaces::Mesh> rendered;  // the mesh the scene was built from
};

struct VolumeData {
    volume::BrickedVolume vol;
    // The last shaded scene's gradient bricks (of vol), offered to the next scene: a TF
    // change that shows no new brick reuses them.
    std::shared_ptr<const volume::GradientBricks> gradients;
};

struct SpheresData {
    std::shared_ptr<SphereScene> scene;
};

struct SceneData {
    SceneKind kind = SceneKind::Points;
    std::string source;
    AABB bounds;
    DefaultView view;
    Stats info, load;
    std::vector<std::string> warnings;
    bool keepSource = true;
    bool progress = true;
    // One build or render at a time on the data (sessions on one scene take turns).
    std::mutex mutex;
    PointData points;
    MeshData mesh;
    VolumeData volume;
    SpheresData spheres;
};

}  // namespace rtfact::engine::detail
