#include "engine/scene.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/util/input_file.h"
#include "engine/scene_data.h"
#include "engine/usage_error.h"
#include "points/point_cloud_io.h"
#include "surfaces/mesh_loader.h"
#include "volume/default_transfer_function.h"
#include "volume/value_histogram.h"

namespace rtfact::engine {

using namespace rtfact::surfaces;

using detail::SceneData;

namespace {

std::string fmt(const char* f, auto... args) {
    char buf[512];
    std::snprintf(buf, sizeof buf, f, args...);
    return buf;
}

std::string boundsText(const AABB& b) {
    return fmt("[%g %g %g] - [%g %g %g]", double(b.lo.x), double(b.lo.y), double(b.lo.z), double(b.hi.x),
               double(b.hi.y), double(b.hi.z));
}

std::shared_ptr<SceneData> makeData(SceneKind kind, std::string source) {
    auto d = std::make_shared<SceneData>();
    d->kind = kind;
    d->source = std::move(source);
    return d;
}

// What `rtfact volume` renders with when no TF is given.
volume::DefaultTransferFunction defaultTF(const volume::BrickedVolume& v) {
    return volume::chooseDefaultTransferFunction(v.meta, volume::histogramOf(v), volume::VolumeMode::DVR,
                                                 volume::typicalDepthVoxels(v.dims, v.spacing));
}

// The view presets of point clouds (LAS convention: z up, y north).
DefaultView pointView(const AABB& focus, const std::string& preset) {
    if (preset == "top") return {focus, {0.0f, 0.0f, 1.0f}, {0, 1, 0}};
    if (preset == "oblique") return {focus, {0.35f, -0.8f, 0.75f}, {0, 0, 1}};
    if (preset == "front") return {focus, {0.0f, -1.0f, 0.08f}, {0, 0, 1}};
    if (preset == "side") return {focus, {1.0f, 0.0f, 0.08f}, {0, 0, 1}};
    return {focus};
}

void finishPoints(SceneData& d) {
    const points::PointCloud& c = d.points.cloud;
    d.bounds = c.bounds();
    d.view.focus = d.bounds;
    d.info.add("kind", "points");
    d.info.add("points", (unsigned long long)c.size());
    d.info.add("bounds", boundsText(d.bounds));
    d.info.add("normals", c.normals.empty() ? "none" : "yes");
    d.info.add("colors", c.colors.empty() ? "none" : "yes");
    d.info.add("radii", c.radii.empty() ? "none" : "yes");
    if (!c.classes.empty()) d.info.add("classification", "yes");
    if (!c.scalars.empty()) {
        std::string names;
        for (const points::ScalarField& f : c.scalars) names += (names.empty() ? "" : " ") + f.name;
        d.info.add("attributes", names);
    }
    if (!c.crs.empty()) d.info.add("crs", c.crs.size() > 80 ? c.crs.substr(0, 77) + "..." : c.crs);
    // A flat georeferenced cloud (an airborne tile: z up, extent far below x/y) is seen
    // from above at an angle; head-on it would be a line.
    const Vec3f e = d.bounds.extent();
    const bool georeferenced = !c.crs.empty() || c.origin != std::array<double, 3>{0, 0, 0};
    if (georeferenced && e.z < 0.25f * std::max(e.x, e.y)) d.view = pointView(d.bounds, "oblique");
}

void finishMesh(SceneData& d) {
    const Mesh& m = *d.mesh.mesh;
    // The triangles' box (what the BVH bounds): unreferenced vertices do not count.
    AABB b;
    for (uint32_t i : m.indices) b.extend(m.positions[i]);
    d.bounds = b;
    d.view.focus = b;
    d.info.add("kind", "mesh");
    d.info.add("vertices", (unsigned long long)m.positions.size());
    d.info.add("triangles", (unsigned long long)m.triangles());
    d.info.add("bounds", boundsText(b));
    d.info.add("materials", (unsigned long long)m.materials.size());
}

void finishVolume(SceneData& d) {
    const volume::BrickedVolume& v = d.volume.vol;
    d.bounds = v.bounds();
    d.view = {d.bounds, {0.45f, -1.0f, 0.35f}, {0, 0, 1}};
    const auto [lo, hi] = v.valueRange();
    d.info.add("kind", "volume");
    d.info.add("dims", fmt("%d x %d x %d", v.dims[0], v.dims[1], v.dims[2]));
    d.info.add("voxels", (unsigned long long)v.voxelCount());
    d.info.add("spacing", fmt("%g %g %g", double(v.spacing.x), double(v.spacing.y), double(v.spacing.z)));
    d.info.add("bounds", boundsText(d.bounds));
    d.info.add("range", fmt("%g .. %g", double(lo), double(hi)));
    d.info.add("memory_mb", double(v.memoryBytes()) / 1048576.0);
    d.info.add("tf_default", defaultTF(v).describe());
}

}  // namespace

const char* kindName(SceneKind k) {
    switch (k) {
        case SceneKind::Points:
            return "points";
        case SceneKind::Mesh:
            return "mesh";
        case SceneKind::Volume:
            return "volume";
        default:
            return "spheres";
    }
}

SceneKind Scene::kind() const { return data->kind; }
AABB Scene::bounds() const { return data->bounds; }
const Stats& Scene::info() const { return data->info; }
const Stats& Scene::loadStats() const { return data->load; }
const std::vector<std::string>& Scene::warnings() const { return data->warnings; }
const std::string& Scene::source() const { return data->source; }

DefaultView Scene::defaultView(const Settings& s) const {
    DefaultView v = data->view;
    if (data->kind == SceneKind::Volume) {
        // the clipped box, as the volume scene bounds it (index space -> world)
        const volume::BrickedVolume& vol = data->volume.vol;
        Vec3f lo, hi;
        for (int a = 0; a < 3; ++a) {
            const float n1 = float(vol.dims[a] - 1);
            lo[a] = std::clamp(s.volume.clipLo[a], 0.0f, 1.0f) * n1;
            hi[a] = std::clamp(s.volume.clipHi[a], 0.0f, 1.0f) * n1;
        }
        v.focus = AABB{vol.origin + lo * vol.spacing, vol.origin + hi * vol.spacing};
    }
    if (data->kind == SceneKind::Points && s.points.view != "auto") {
        if (s.points.view != "top" && s.points.view != "oblique" && s.points.view != "front" && s.points.view != "side")
            throw UsageError("--view", "'" + s.points.view + "' is not one of auto, top, oblique, front, side");
        v = pointView(v.focus, s.points.view);
    }
    return v;
}

Scene open(const std::vector<std::string>& files, const OpenOptions& opt) {
    if (files.empty()) throw UsageError("FILE", "no input file");
    SceneKind kind;
    if (opt.kind) {
        kind = *opt.kind;
    } else {
        // Before anything opens them: a named pipe would block every reader.
        for (const std::string& f : files) requireFileOrDirectory(f);
        if (files.size() == 1 && volume::looksLikeVolume(files[0]))
            kind = SceneKind::Volume;
        else if (meshFileKind(files[0]) != MeshFileKind::NotMesh)
            kind = SceneKind::Mesh;
        else if (files.size() == 1 && points::probePointFile(files[0]))
            kind = SceneKind::Points;
        else
            throw Error(files[0], "unknown file type");
    }
    if (kind != SceneKind::Mesh && files.size() != 1)
        throw UsageError("FILE", std::string("a ") + kindName(kind) + " scene is opened from one file");
    std::string source = files[0];
    for (size_t i = 1; i < files.size(); ++i) source += " " + files[i];
    auto d = makeData(kind, source);
    d->keepSource = opt.keepSource;
    d->progress = opt.progress;
    const auto t0 = std::chrono::steady_clock::now();
    switch (kind) {
        case SceneKind::Points: {
            d->points.cloud = points::loadPointCloud(files[0], opt.points);
            const double ms = msSince(t0);
            const size_t n = d->points.cloud.size();
            d->load.add("load_ms", ms);
            d->load.add("points", (unsigned long long)n);
            d->load.add("load_points_per_s", ms > 0 ? double(n) / (ms * 1e-3) : 0.0);
            d->load.add("dropped_nonfinite", (unsigned long long)d->points.cloud.droppedNonFinite);
            // Points lost on load are worth one line (all lost is an error in the loader).
            if (std::string w = points::droppedPointsMessage(files[0], d->points.cloud); !w.empty())
                d->warnings.push_back(std::move(w));
            finishPoints(*d);
            break;
        }
        case SceneKind::Mesh:
            d->mesh.mesh = std::make_shared<Mesh>(loadMeshes(files));
            d->load.add("load_ms", msSince(t0));
            finishMesh(*d);
            break;
        case SceneKind::Volume: {
            volume::VolumeLoadOptions lo = opt.volume;
            lo.progress = opt.progress;
            d->volume.vol = volume::loadBrickedVolume(files[0], lo);
            d->load.add("load_ms", msSince(t0));
            finishVolume(*d);
            break;
        }
        default:
            throw UsageError("FILE", "the sphere demo is not opened from a file (engine::spheres)");
    }
    return Scene{d};
}

Scene pointsFromArrays(std::vector<Vec3f> positions, std::vector<Vec3f> colors, std::vector<Vec3f> normals,
                       std::vector<float> radii) {
    const size_t n = positions.size();
    auto sized = [n](size_t m, const char* what) {
        if (m != 0 && m != n)
            throw UsageError(what, "has " + std::to_string(m) + " entries for " + std::to_string(n) + " points");
    };
    sized(colors.size(), "colors");
    sized(normals.size(), "normals");
    sized(radii.size(), "radii");
    if (n == 0) throw UsageError("positions", "no points");
    auto d = makeData(SceneKind::Points, "");
    points::PointCloud& c = d->points.cloud;
    for (const Vec3f& p : positions)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw UsageError("positions", "non-finite coordinate");
    c.positions = std::move(positions);
    c.normals = std::move(normals);
    c.radii = std::move(radii);
    c.colors.reserve(colors.size());
    for (const Vec3f& col : colors) {
        auto b = [](float v) { return uint8_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f); };
        c.colors.push_back({b(col.x), b(col.y), b(col.z)});
    }
    c.format = "memory";
    finishPoints(*d);
    return Scene{d};
}

Scene meshFromArrays(std::vector<Vec3f> vertices, std::vector<uint32_t> triangles) {
    if (triangles.size() % 3 != 0) throw UsageError("triangles", "index count is not a multiple of 3");
    auto d = makeData(SceneKind::Mesh, "");
    auto m = std::make_shared<Mesh>();
    m->source = "mesh arrays";
    m->positions = std::move(vertices);
    m->indices = std::move(triangles);
    m->validate();
    m->computeNormals();
    m->normalsComputed = true;
    d->mesh.mesh = std::move(m);
    finishMesh(*d);
    return Scene{d};
}

Scene volumeFromArray(std::vector<float> values, std::array<int, 3> dims, Vec3f spacing) {
    for (int a = 0; a < 3; ++a)
        if (dims[a] < 1) throw UsageError("dims", "every dimension must be at least 1");
    const uint64_t n = uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]);
    if (n != values.size())
        throw UsageError("values",
                         "has " + std::to_string(values.size()) + " entries for " + std::to_string(n) + " voxels");
    if (!(spacing.x > 0 && spacing.y > 0 && spacing.z > 0)) throw UsageError("spacing", "must be positive");
    volume::VolumeGrid g;
    for (int a = 0; a < 3; ++a) g.dims[a] = dims[a];
    g.spacing = spacing;
    g.storage = volume::Storage::F32;
    g.sourceType = "f32";
    g.bytes.resize(values.size() * sizeof(float));
    std::memcpy(g.bytes.data(), values.data(), g.bytes.size());
    values = {};
    auto d = makeData(SceneKind::Volume, "");
    try {
        d->volume.vol = volume::brickVolume(g, true);
    } catch (const Error& e) {
        throw Error("volume array", e.what());
    }
    finishVolume(*d);
    return Scene{d};
}

Scene spheres(int count) {
    if (count < 0) throw UsageError("--count", "must not be negative");
    auto d = makeData(SceneKind::Spheres, "");
    const auto t0 = std::chrono::steady_clock::now();
    d->spheres.scene = std::make_shared<SphereScene>(SphereScene::demo(count));
    d->load.add("load_ms", 0.0);
    d->load.add("build_ms", msSince(t0));
    const SphereScene& s = *d->spheres.scene;
    d->load.add("primitives", (unsigned long long)s.spheres.size());
    d->bounds = s.bounds();
    // Fit the view to the small spheres, not the ground sphere.
    AABB focus;
    for (size_t i = 1; i < s.spheres.size(); ++i) focus.extend(s.spheres[i].bounds());
    if (focus.isEmpty()) focus = AABB{{-1, 0, -1}, {1, 1, 1}};
    d->view = {focus, {0.0f, 0.8f, 1.0f}, {0, 1, 0}};
    d->info.add("kind", "spheres");
    d->info.add("spheres", (unsigned long long)s.spheres.size());
    d->info.add("bounds", boundsText(d->bounds));
    return Scene{d};
}

Scene pointsFromCloud(points::PointCloud cloud, const std::string& source) {
    const size_t n = cloud.positions.size();
    if (n == 0) throw UsageError(source, "no points");
    auto sized = [&](size_t m, const char* what) {
        if (m != 0 && m != n)
            throw UsageError(source, std::string(what) + " has " + std::to_string(m) + " entries for " +
                                         std::to_string(n) + " points");
    };
    sized(cloud.colors.size(), "colors");
    sized(cloud.normals.size(), "normals");
    sized(cloud.radii.size(), "radius");
    sized(cloud.intensities.size(), "intensity");
    auto finite3 = [](const Vec3f& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); };
    for (size_t i = 0; i < n; ++i)
        if (!finite3(cloud.positions[i]))
            throw UsageError(source, "non-finite coordinate at point " + std::to_string(i));
    for (size_t i = 0; i < cloud.normals.size(); ++i)
        if (!finite3(cloud.normals[i])) throw UsageError(source, "non-finite normal at point " + std::to_string(i));
    for (size_t i = 0; i < cloud.radii.size(); ++i)
        if (!(std::isfinite(cloud.radii[i]) && cloud.radii[i] > 0))
            throw UsageError(source, "radius at point " + std::to_string(i) + " is not a positive finite number");
    for (size_t i = 0; i < cloud.intensities.size(); ++i)
        if (!std::isfinite(cloud.intensities[i]))
            throw UsageError(source, "non-finite intensity at point " + std::to_string(i));
    auto d = makeData(SceneKind::Points, "");
    d->points.cloud = std::move(cloud);
    d->points.cloud.format = "memory";
    finishPoints(*d);
    return Scene{d};
}

namespace {

// Stored value of a view's voxel: i16 shifted into u16 (offset -32768, as the loaders).
template <class T>
float viewStored(const uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    if constexpr (std::is_same_v<T, int16_t>)
        return float(int(v) + 32768);
    else
        return float(v);
}

template <class T>
void brickView(const VolumeView& view, volume::BrickedVolume& v, const std::string& source) {
    using BV = volume::BrickedVolume;
    const auto* base = static_cast<const uint8_t*>(view.data);
    const auto& dims = view.dims;
    auto at = [&](int x, int y, int z) {
        x = std::min(x, dims[0] - 1);
        y = std::min(y, dims[1] - 1);
        z = std::min(z, dims[2] - 1);
        return viewStored<T>(base + int64_t(x) * view.strides[0] + int64_t(y) * view.strides[1] +
                             int64_t(z) * view.strides[2]);
    };
    if constexpr (std::is_same_v<T, float>) {
        for (int z = 0; z < dims[2]; ++z)
            for (int y = 0; y < dims[1]; ++y)
                for (int x = 0; x < dims[0]; ++x)
                    if (!std::isfinite(at(x, y, z)))
                        throw UsageError(source, fmt("non-finite value at voxel (x=%d, y=%d, z=%d)", x, y, z));
    }
    // All-zero bricks share brick 0 (as brickVolume does); the others are filled in order
    // into a pool reserved once, so no dense copy and no pool regrowth.
    const size_t nb = v.brickCount();
    std::vector<uint8_t> zero(nb, 0);
    tbb::parallel_for(size_t(0), nb, [&](size_t b) {
        const int bx = int(b % size_t(v.nb[0])), by = int((b / size_t(v.nb[0])) % size_t(v.nb[1])),
                  bz = int(b / (size_t(v.nb[0]) * size_t(v.nb[1])));
        bool allZero = true;
        for (int k = 0; k < BV::kEdge && allZero; ++k)
            for (int j = 0; j < BV::kEdge && allZero; ++j)
                for (int i = 0; i < BV::kEdge && allZero; ++i)
                    allZero = at(bx * BV::kCells + i, by * BV::kCells + j, bz * BV::kCells + k) == 0.0f;
        zero[b] = allZero;
    });
    size_t filled = 0;
    for (uint8_t z : zero) filled += z ? 0 : 1;
    v.pool.reserve((filled + 1) * size_t(BV::kBrick) * size_t(volume::storageBytes(v.storage)) + 64);
    for (int bz = 0; bz < v.nb[2]; ++bz)
        for (int by = 0; by < v.nb[1]; ++by)
            for (int bx = 0; bx < v.nb[0]; ++bx)
                if (!zero[v.brickIndex(bx, by, bz)]) volume::BrickBuilder::addBrick(v, bx, by, bz, at);
}

}  // namespace

Scene volumeFromView(const VolumeView& view, const std::string& source) {
    volume::Storage storage;
    if (view.type == "u8")
        storage = volume::Storage::U8;
    else if (view.type == "u16" || view.type == "i16")
        storage = volume::Storage::U16;
    else if (view.type == "f32")
        storage = volume::Storage::F32;
    else
        throw UsageError(source, "voxel type '" + view.type + "' is not one of u8, u16, i16, f32");
    if (!view.data) throw UsageError(source, "no voxel data");
    for (int a = 0; a < 3; ++a)
        if (view.dims[a] < 2)
            throw UsageError(source, fmt("needs at least 2 voxels along every axis, got %d x %d x %d (x, y, z)",
                                         view.dims[0], view.dims[1], view.dims[2]));
    const Vec3f& sp = view.spacing;
    if (!(sp.x > 0 && sp.y > 0 && sp.z > 0 && std::isfinite(sp.x) && std::isfinite(sp.y) && std::isfinite(sp.z)))
        throw UsageError(source, "spacing must be positive and finite");
    const Vec3f& o = view.origin;
    if (!(std::isfinite(o.x) && std::isfinite(o.y) && std::isfinite(o.z)))
        throw UsageError(source, "origin must be finite");
    auto d = makeData(SceneKind::Volume, "");
    volume::BrickedVolume& v = d->volume.vol;
    volume::BrickBuilder::init(v, view.dims.data(), storage);
    v.spacing = sp;
    v.origin = o;
    v.sourceType = view.type;
    if (view.type == "i16") v.offset = -32768.0f;
    if (view.type == "u8")
        brickView<uint8_t>(view, v, source);
    else if (view.type == "u16")
        brickView<uint16_t>(view, v, source);
    else if (view.type == "i16")
        brickView<int16_t>(view, v, source);
    else
        brickView<float>(view, v, source);
    try {
        volume::BrickBuilder::finish(v);
    } catch (const Error& e) {
        throw Error(source, e.what());
    }
    finishVolume(*d);
    return Scene{d};
}

}  // namespace rtfact::engine
