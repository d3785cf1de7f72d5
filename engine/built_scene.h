// The structures the engine prepares and builds for a scene and its settings, for code
// that drives them ray by ray instead of rendering images: the peer benchmarks
// (rtfact-bench compares them with Embree and OpenVDB on identical rays) and the domain
// tests. Loading, preparation, defaults (TF, window, iso) and builds stay the engine's.
#pragma once
#include <memory>
#include <utility>

#include "core/render/pinhole_camera.h"
#include "engine/scene.h"
#include "points/point_scene.h"
#include "surfaces/mesh.h"
#include "volume/brick_volume.h"
#include "volume/transfer_function.h"
#include "volume/volume_scene.h"

namespace rtfact::engine {

// The point cloud prepared (normals, radii, colours) and built into its LoD kd-tree for
// `settings.points`, as a render of `frame` would use it (estimated normals face its eye).
std::shared_ptr<points::PointScene> builtPoints(const Scene& scene, const Settings& settings, const CameraFrame& frame,
                                                Stats* stats = nullptr);

// The loaded mesh (several files merged). Needs the scene opened with keepSource.
std::shared_ptr<const surfaces::Mesh> loadedMesh(const Scene& scene);

// What a volume render of `settings.volume` uses: the transfer function (given or chosen
// from the data), the window, the TF table and the march settings.
struct VolumeSetup {
    volume::VolumeRenderSettings render;
    volume::TransferFunction tf;
    std::pair<float, float> window;
    volume::TFTable table;
};
struct BuiltVolume {
    const volume::BrickedVolume* volume = nullptr;  // owned by the scene
    VolumeSetup setup;
};
BuiltVolume builtVolume(const Scene& scene, const Settings& settings, Stats* stats = nullptr);

}  // namespace rtfact::engine
