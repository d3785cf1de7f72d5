// What a render of each kind of scene is asked for: one settings type per domain, with
// the library's defaults. Integrator and mode names map to types through one table per
// domain (pointIntegrators() ... in the render units); unknown names throw UsageError.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/math/aabb.h"
#include "core/math/vec3f.h"
#include "points/point_prepare.h"
#include "surfaces/mesh.h"
#include "volume/transfer_function.h"

namespace rtfact::engine {

enum class SceneKind { Points, Mesh, Volume, Spheres };
const char* kindName(SceneKind k);

struct PointSettings {
    std::string integrator = "eyelight";                // pointIntegrators()
    points::ColorMode color = points::ColorMode::Auto;  // auto: the file's colours if real, else elevation
    std::string colorAttribute;                         // ColorMode::Attribute: the scalar's name
    std::string colormap;                               // empty: the mode's default (points::colormapNames())
    std::optional<std::array<float, 2>> colorRange;     // none: robust percentiles
    std::optional<float> edl;      // eye-dome lighting strength (0: off); none: on for clouds without file normals
    std::string view = "auto";     // default camera: auto|top|oblique|front|side
    bool lod = true;               // off: full detail
    float lodQuality = 2.0f;       // node answered by its representative when size < footprint x Q
    std::string normals = "auto";  // auto|estimate|file
    float radius = 0.0f;           // > 0: one radius for every point
    float radiusFactor = 1.0f;     // times the spacing estimate or the file's radii
    int leafSize = 8;
    // kd: the LoD kd-tree (~31 bytes per point); wide: the wide BVH of 8-disc blocks with
    // child summaries in the parents, median split (~65 bytes per point, traces packets
    // faster, docs/benchmarks.md). Full-detail images are the same with both.
    std::string accel = "kd";
    int aoSamples = 8;
};

// A light of the mesh scene; point lights are scaled so that the scene centre receives
// an irradiance of 0.85 (white surfaces facing the light stay below clipping).
struct LightSpec {
    enum class Kind { Point, Directional } kind = Kind::Point;
    Vec3f v;  // position or direction (towards which the light travels)
};

struct MeshSettings {
    std::string integrator = "direct";               // meshIntegrators()
    std::vector<LightSpec> lights;                   // empty: a key light above and left of the camera
    std::optional<surfaces::MeshMaterial> material;  // replaces every material (see materialOverride)
    std::string bvh = "sah";                         // sah|kdtree
    int aoSamples = 16;
    int maxDepth = 6;
    std::string secondary = "auto";  // traversal of AO / bounce rays: auto|wide|packet
};

struct VolumeSettings {
    std::string mode = "dvr";                    // volumeModes()
    std::optional<volume::TransferFunction> tf;  // none: chosen from the data
    std::optional<float> window, level, iso;     // data units; none: from the TF / data
    float step = 0.5f;                           // voxels
    Vec3f clipLo{0, 0, 0}, clipHi{1, 1, 1};      // fractions of each axis
    bool skipping = true;
    // Opacity-adaptive steps (dvr, shaded): bricks of low opacity are marched with 2 or 4
    // times the step on the same sample lattice; off: the plain march.
    bool adaptiveSteps = true;
    // Pre-integrated transfer function (dvr, shaded): each sample composites the segment
    // from the previous one, the value taken as linear between them.
    bool preintegrated = false;
    // Data-parallel ranks: samples on the lattice of this world box (docs/mpi.md).
    std::optional<AABB> lattice;
};

struct SpheresSettings {
    std::string integrator = "direct";  // spheresIntegrators()
};

// The settings of every domain; a session uses the one of its scene's kind.
struct Settings {
    PointSettings points;
    MeshSettings mesh;
    VolumeSettings volume;
    SpheresSettings spheres;
};

// The closed name tables (what the CLI offers).
const std::vector<std::string>& pointIntegrators();
const std::vector<std::string>& pointAccels();
const std::vector<std::string>& meshIntegrators();
const std::vector<std::string>& volumeModes();
const std::vector<std::string>& spheresIntegrators();

// lambert[:kd] | mirror[:ks] | glass[:ior]: the replacement material of --material.
surfaces::MeshMaterial lambertMaterial(std::optional<Vec3f> kd = std::nullopt);
surfaces::MeshMaterial mirrorMaterial(std::optional<Vec3f> ks = std::nullopt);
surfaces::MeshMaterial glassMaterial(float ior = 1.5f);

}  // namespace rtfact::engine
