// engine::fileInfo: `rtfact info FILE`, asked of each domain in turn (volume, mesh,
// point cloud) without rendering.
#include <algorithm>
#include <cstdio>

#include "core/io/file_helpers.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "engine/scene.h"
#include "points/las_io.h"
#include "points/point_cloud_io.h"
#include "surfaces/mesh_loader.h"
#include "volume/default_transfer_function.h"
#include "volume/value_histogram.h"

namespace rtfact::engine {

using namespace rtfact::surfaces;

namespace {

using Lines = std::vector<std::pair<std::string, std::string>>;

std::string fmt(const char* f, auto... args) {
    char buf[1024];
    std::snprintf(buf, sizeof buf, f, args...);
    return buf;
}

Lines volumeInfo(const std::string& file) {
    using namespace volume;
    VolumeLoadOptions lo;
    lo.progress = false;
    const VolumeGrid g = loadVolume(file, lo);
    const VolumeSummary s = summarize(g, 8);
    Lines l;
    l.emplace_back("file", file);
    l.emplace_back("kind", "volume");
    l.emplace_back("dims", fmt("%d x %d x %d", g.dims[0], g.dims[1], g.dims[2]));
    l.emplace_back("voxels", fmt("%zu", g.voxelCount()));
    l.emplace_back("type", fmt("%s (stored as %s, value = stored * %g + %g)", g.sourceType.c_str(),
                               storageName(g.storage), double(g.scale), double(g.offset)));
    l.emplace_back("spacing", fmt("%g %g %g", double(g.spacing.x), double(g.spacing.y), double(g.spacing.z)));
    l.emplace_back("origin", fmt("%g %g %g", double(g.origin.x), double(g.origin.y), double(g.origin.z)));
    const AABB b = g.bounds();
    l.emplace_back("bounds", fmt("[%g %g %g] - [%g %g %g]", double(b.lo.x), double(b.lo.y), double(b.lo.z),
                                 double(b.hi.x), double(b.hi.y), double(b.hi.z)));
    l.emplace_back("range", fmt("%g .. %g (mean %g)", double(s.lo), double(s.hi), s.mean));
    l.emplace_back("memory_mb", fmt("%.2f", double(g.memoryBytes()) / 1048576.0));
    std::string h;
    for (uint64_t n : s.histogram)
        h += fmt("%s%.1f", h.empty() ? "" : " ", 100.0 * double(n) / double(std::max<size_t>(g.voxelCount(), 1)));
    l.emplace_back("histogram (8 bins over the range, % of voxels)", h);
    if (!g.meta.modality.empty()) l.emplace_back("modality", g.meta.modality + " (" + g.meta.modalitySource + ")");
    // what `rtfact volume FILE` renders with when no --tf is given
    const DefaultTransferFunction d =
        chooseDefaultTransferFunction(g.meta, histogramOf(g), VolumeMode::DVR, typicalDepthVoxels(g.dims, g.spacing));
    l.emplace_back("tf_default", d.describe());
    return l;
}

Lines meshInfo(const std::string& file, MeshFileKind kind) {
    const char* names[] = {"", "PLY", "OBJ", "STL", "VTK legacy", "VTP"};
    const Mesh m = loadMesh(file);
    const AABB b = m.bounds();
    Lines l;
    l.emplace_back("file", file);
    l.emplace_back("type", fmt("mesh (%s)", names[int(kind)]));
    l.emplace_back("vertices", fmt("%zu", m.positions.size()));
    l.emplace_back("triangles", fmt("%zu", m.triangles()));
    l.emplace_back("bounds", fmt("[%g, %g, %g] - [%g, %g, %g]", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z));
    l.emplace_back("normals", m.normalsComputed ? "computed (none in file)" : "from file");
    l.emplace_back("uvs", m.uvs.empty() ? "no" : "yes");
    l.emplace_back("colors", m.colors.empty() ? "no" : "yes");
    l.emplace_back("materials", fmt("%zu", m.materials.size()));
    for (const MeshMaterial& mm : m.materials)
        l.emplace_back("  " + mm.name, fmt("kd=%g,%g,%g%s%s", mm.kd.x, mm.kd.y, mm.kd.z,
                                           mm.diffuseMap.empty() ? "" : " map_Kd=", mm.diffuseMap.c_str()));
    return l;
}

Lines pointsInfo(const std::string& file, const points::PointFileInfo& info) {
    Lines l;
    l.emplace_back("file", file);
    l.emplace_back("type", "point cloud");
    l.emplace_back("format", info.format);
    l.emplace_back("points", fmt("%zu", info.points));
    std::string props;
    for (const auto& p : info.properties) props += (props.empty() ? "" : " ") + p;
    l.emplace_back("properties", props);
    return l;
}

// LAS/LAZ: the header, the counts by return and class of the points themselves, the CRS
// text and every VLR.
Lines lasInfo(const std::string& file) {
    static const char* classNames[] = {"never classified",  "unclassified",    "ground",         "low vegetation",
                                       "medium vegetation", "high vegetation", "building",       "low noise",
                                       "reserved",          "water",           "rail",           "road surface",
                                       "reserved",          "wire guard",      "wire conductor", "transmission tower",
                                       "wire connector",    "bridge deck",     "high noise"};
    const points::las::Summary s = points::las::summarize(file);
    const points::las::Header& h = s.header;
    Lines l;
    l.emplace_back("file", file);
    l.emplace_back("type", "point cloud");
    l.emplace_back("format", fmt("%s %d.%d, point format %d, %d-byte records", h.compressed ? "LAZ" : "LAS",
                                 h.versionMajor, h.versionMinor, h.pointFormat, h.recordLength));
    l.emplace_back("points", fmt("%llu", (unsigned long long)h.pointCount));
    std::string ret;
    for (auto [r, n] : s.byReturn) ret += fmt("%s%d: %llu", ret.empty() ? "" : ", ", r, (unsigned long long)n);
    l.emplace_back("by return", ret);
    std::string cls;
    for (auto [c, n] : s.byClass)
        cls += fmt("%s%d %s: %llu", cls.empty() ? "" : ", ", c, c < 19 ? classNames[c] : "user defined",
                   (unsigned long long)n);
    l.emplace_back("by class", cls);
    l.emplace_back("bounds", fmt("[%.15g %.15g %.15g] - [%.15g %.15g %.15g]", h.min[0], h.min[1], h.min[2], h.max[0],
                                 h.max[1], h.max[2]));
    l.emplace_back("scale", fmt("%.15g %.15g %.15g", h.scale[0], h.scale[1], h.scale[2]));
    l.emplace_back("offset", fmt("%.15g %.15g %.15g", h.offset[0], h.offset[1], h.offset[2]));
    l.emplace_back("crs", s.crs.empty() ? "none" : s.crs);
    l.emplace_back("software", h.software + (h.systemId.empty() ? "" : " (" + h.systemId + ")"));
    for (const points::las::ExtraField& e : s.extra) l.emplace_back("extra bytes", e.name);
    for (const points::las::Vlr& v : h.vlrs)
        l.emplace_back(v.extended ? "evlr" : "vlr",
                       fmt("%s %u (%llu bytes)%s%s", v.userId.c_str(), v.recordId, (unsigned long long)v.size,
                           v.description.empty() ? "" : ": ", v.description.c_str()));
    return l;
}

}  // namespace

std::vector<std::pair<std::string, std::string>> fileInfo(const std::string& file) {
    // Before any domain opens it: a named pipe would block every reader.
    requireFileOrDirectory(file);
    if (volume::looksLikeVolume(file)) return volumeInfo(file);
    if (const MeshFileKind k = meshFileKind(file); k != MeshFileKind::NotMesh) return meshInfo(file, k);
    if (const std::string e = io::lowerExt(file); e == ".las" || e == ".laz") return lasInfo(file);
    if (const auto info = points::probePointFile(file)) return pointsInfo(file, *info);
    throw Error(file, "unknown file type");
}

}  // namespace rtfact::engine
