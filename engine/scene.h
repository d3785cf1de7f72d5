// engine::Scene: a loaded data set of any kind (point cloud, mesh, volume, the sphere
// demo) with its bounds, what it holds (info()) and the timings of loading. Preparation
// (normals, radii) and acceleration structures are made by the render session for its
// settings and kept in the scene until settings that change them come.
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/math/aabb.h"
#include "engine/settings.h"
#include "engine/stats.h"
#include "points/point_cloud.h"
#include "points/point_cloud_io.h"
#include "volume/volume_io.h"

namespace rtfact::engine {

namespace detail {
struct SceneData;
}

// How the camera is fitted by default: to `focus`, looking from `viewDir` with `up`.
struct DefaultView {
    AABB focus;
    Vec3f viewDir{0.6f, 0.45f, 1.0f}, up{0, 1, 0};
};

class Scene {
   public:
    SceneKind kind() const;
    // Bounds of the data as loaded (point positions, mesh vertices, volume box).
    AABB bounds() const;
    // The default camera's target box and direction for these settings (a volume's
    // view fits its clipped box).
    DefaultView defaultView(const Settings& settings = {}) const;
    // What the scene holds: kind, counts, bounds, value range, default TF ...
    const Stats& info() const;
    // Load statistics (load_ms, points, ...), in the order `rtfact --stats` prints them.
    const Stats& loadStats() const;
    // Non-fatal findings while loading (e.g. points dropped), one line each.
    const std::vector<std::string>& warnings() const;
    // The file(s) it came from ("" for in-memory data).
    const std::string& source() const;

    std::shared_ptr<detail::SceneData> data;
};

struct OpenOptions {
    std::optional<SceneKind> kind;     // none: from the file (volume, then mesh, then point cloud)
    volume::VolumeLoadOptions volume;  // raw layout, spacing, grid name; .progress is set from `progress`
    bool progress = true;              // progress bars on stderr
    // Keep the loaded cloud/mesh after building, so that settings which change the
    // build (radii, colour mode, material, BVH) can rebuild; off saves the memory.
    bool keepSource = true;
    points::LoadFilter points;  // point clouds: --classes --returns --crop, applied while loading
};

// Opens a point cloud (.ply without faces, .pcd, .xyz/.pts, .las/.laz), meshes (several are merged),
// or a volume (.raw .mhd .nrrd .nii .vti .vdb, a DICOM directory). Throws Error.
Scene open(const std::vector<std::string>& files, const OpenOptions& opt = {});

// In-memory data (the Python module's entry points). Empty optional arrays: absent.
Scene pointsFromArrays(std::vector<Vec3f> positions, std::vector<Vec3f> colors = {}, std::vector<Vec3f> normals = {},
                       std::vector<float> radii = {});
Scene meshFromArrays(std::vector<Vec3f> vertices, std::vector<uint32_t> triangles);
Scene volumeFromArray(std::vector<float> values, std::array<int, 3> dims, Vec3f spacing = {1, 1, 1});
// The analytic demo: a ground sphere and `count` small ones.
Scene spheres(int count);

// `rtfact info FILE`: what a file holds, as (key, value) lines, without rendering it.
std::vector<std::pair<std::string, std::string>> fileInfo(const std::string& file);

// In-memory data without intermediate copies (the Python module's numpy inputs).

// A point cloud the caller filled: positions plus optional colours, normals, radii and
// intensities of the same count (empty: absent). Throws UsageError(`source`, ...) for a
// size mismatch, no points, non-finite values or radii <= 0.
Scene pointsFromCloud(points::PointCloud cloud, const std::string& source = "point arrays");

// A dense volume read in place through byte strides, so any memory layout (C or Fortran
// order, a strided slice) is bricked without a dense copy; u8/u16 stay 8/16-bit, i16 is
// stored shifted into u16 (as the file loaders do), f32 as floats. The memory is only
// read during the call.
struct VolumeView {
    const void* data = nullptr;
    std::string type;                  // u8 | u16 | i16 | f32
    std::array<int, 3> dims{};         // voxels along x, y, z
    std::array<int64_t, 3> strides{};  // bytes between neighbours along x, y, z
    Vec3f spacing{1, 1, 1}, origin{0, 0, 0};
};
// Throws UsageError(`source`, ...) for a bad type, dims < 2, spacing <= 0 or non-finite voxels.
Scene volumeFromView(const VolumeView& view, const std::string& source = "volume array");

}  // namespace rtfact::engine
