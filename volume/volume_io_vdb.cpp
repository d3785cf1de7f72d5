// OpenVDB grids: the named (or first) float grid, densified over its active bounding box.
// OpenVDB headers stay in this file (and in the benchmark).
#include <openvdb/openvdb.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/util/error.h"
#include "core/util/huge_pages.h"
#include "core/util/input_file.h"
#include "volume/vdb_file_check.h"
#include "volume/volume_io.h"

namespace rtfact::volume {

namespace {

// The named (or first) float grid of the file, read by OpenVDB once our own structural check
// (vdb_file_check.h) has passed: OpenVDB trusts the lengths and counts in the file and, on a
// truncated or corrupted one, reads past its end, allocates by garbage lengths or stalls.
openvdb::FloatGrid::Ptr readFloatGrid(const std::string& path, const VolumeLoadOptions& opt, std::string& name) {
    requireRegularFile(path);  // a FIFO would block the open
    checkVdbFile(path);
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid;
    name.clear();
    try {
        openvdb::io::File file(path);
        file.open(false);  // no delayed loading: corrupt files fail here, not later
        const openvdb::GridPtrVecPtr metas = file.readAllGridMetadata();  // keep alive while iterating
        for (auto& m : *metas) {
            if (!opt.grid.empty() && m->getName() != opt.grid) continue;
            if (m->valueType() != "float") {
                if (!opt.grid.empty())
                    throw Error(path, "grid '" + opt.grid + "' holds " + m->valueType() + " values, not float");
                continue;
            }
            name = m->getName();
            break;
        }
        if (name.empty())
            throw Error(path, opt.grid.empty() ? "no float grid in the file" : "no grid named '" + opt.grid + "'");
        grid = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(name));
        file.close();
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        std::string what = e.what();
        std::replace(what.begin(), what.end(), '\n', ' ');
        if (what.size() > 300) what = what.substr(0, 300) + "...";
        throw Error(path, "cannot read OpenVDB file: " + what);
    }
    if (!grid) throw Error(path, "grid '" + name + "' is not a float grid");
    return grid;
}

}  // namespace

VolumeGrid loadVDB(const std::string& path, const VolumeLoadOptions& opt) {
    std::string name;
    const openvdb::FloatGrid::Ptr grid = readFloatGrid(path, opt, name);
    const openvdb::CoordBBox bb = grid->evalActiveVoxelBoundingBox();
    if (bb.empty()) throw Error(path, "grid '" + name + "' has no active voxels");
    const int64_t d[3] = {int64_t(bb.dim().x()), int64_t(bb.dim().y()), int64_t(bb.dim().z())};
    checkedVoxelCount(path, d);
    VolumeGrid g;
    for (int a = 0; a < 3; ++a) g.dims[a] = int(d[a]);
    const openvdb::Vec3d vs = grid->voxelSize();
    const openvdb::Vec3d o = grid->indexToWorld(bb.min());
    for (int a = 0; a < 3; ++a) {
        g.spacing[a] = vs[a] > 0 ? float(vs[a]) : 1.0f;
        g.origin[a] = float(o[a]);
    }
    g.sourceType = "f32 (OpenVDB grid '" + name + "', " + std::to_string(grid->activeVoxelCount()) + " active voxels)";
    g.allocate(Storage::F32);
    // Dense layout z fastest in OpenVDB (LayoutZYX); ours is x fastest, so copy by hand
    // through an accessor per z-slab.
    float* out = g.data<float>();
    auto acc = grid->getConstAccessor();
    for (int k = 0; k < g.dims[2]; ++k)
        for (int j = 0; j < g.dims[1]; ++j)
            for (int i = 0; i < g.dims[0]; ++i) {
                const float v = acc.getValue(bb.min() + openvdb::Coord(i, j, k));
                out[g.index(i, j, k)] = std::isfinite(v) ? v : 0.0f;
            }
    return g;
}

}  // namespace rtfact::volume

namespace rtfact::volume {

BrickedVolume loadVDBBricked(const std::string& path, const VolumeLoadOptions& opt) {
    std::string name;
    const openvdb::FloatGrid::Ptr grid = readFloatGrid(path, opt, name);
    if (grid->background() != 0.0f) {
        // Unmarked bricks read as zero; a non-zero background needs the dense path.
        VolumeGrid g = loadVDB(path, opt);
        return brickVolume(g, true);
    }
    const openvdb::CoordBBox bb = grid->evalActiveVoxelBoundingBox();
    if (bb.empty()) throw Error(path, "grid '" + name + "' has no active voxels");
    BrickedVolume v;
    int dims[3];
    for (int a = 0; a < 3; ++a) {
        const int64_t d = int64_t(bb.max()[a]) - int64_t(bb.min()[a]) + 1;
        if (d > (int64_t(1) << 20))
            throw Error(path, "active bounding box is too large (" + std::to_string(d) + " voxels along an axis)");
        dims[a] = int(std::max<int64_t>(d, 2));
    }
    const uint64_t bricks = uint64_t((dims[0] + 6) / 8) * uint64_t((dims[1] + 6) / 8) * uint64_t((dims[2] + 6) / 8);
    if (bricks > (uint64_t(1) << 28))
        throw Error(path, "active bounding box needs too many bricks (" + std::to_string(bricks) + ")");
    BrickBuilder::init(v, dims, Storage::F32);
    const openvdb::Vec3d vs = grid->voxelSize();
    const openvdb::Vec3d o = grid->indexToWorld(bb.min());
    for (int a = 0; a < 3; ++a) {
        v.spacing[a] = vs[a] > 0 ? float(vs[a]) : 1.0f;
        v.origin[a] = float(o[a]);
    }
    v.sourceType =
        "f32 (OpenVDB grid '" + name + "', " + std::to_string(grid->activeVoxelCount()) + " active voxels, sparse)";
    // Mark the bricks whose 9^3 samples touch a leaf node or an active tile.
    std::vector<uint8_t> used(v.brickCount(), 0);
    const openvdb::Coord m0 = bb.min();
    auto markBox = [&](openvdb::Coord lo, openvdb::Coord hi) {
        int b0[3], b1[3];
        for (int a = 0; a < 3; ++a) {
            const int64_t l = int64_t(lo[a]) - m0[a], h = int64_t(hi[a]) - m0[a];
            // brick b holds samples 8b .. 8b+8: b in [ceil((l-8)/8), floor(h/8)]
            auto floorDiv = [](int64_t x) { return x >= 0 ? x / 8 : -((-x + 7) / 8); };
            b0[a] = int(std::clamp<int64_t>(-floorDiv(-(l - 8)), 0, v.nb[a]));
            b1[a] = int(std::clamp<int64_t>(floorDiv(h), -1, v.nb[a] - 1));
        }
        for (int z = b0[2]; z <= b1[2]; ++z)
            for (int y = b0[1]; y <= b1[1]; ++y)
                for (int x = b0[0]; x <= b1[0]; ++x) used[v.brickIndex(x, y, z)] = 1;
    };
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) {
        const openvdb::CoordBBox lb = leaf->getNodeBoundingBox();
        markBox(lb.min(), lb.max());
    }
    for (auto it = grid->tree().cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) continue;
        openvdb::CoordBBox tb;
        it.getBoundingBox(tb);
        markBox(tb.min(), tb.max());
    }
    std::vector<size_t> list;
    for (size_t b = 0; b < used.size(); ++b)
        if (used[b]) list.push_back(b);
    const uint64_t poolFloats = (uint64_t(list.size()) + 1) * uint64_t(BrickedVolume::kBrick);
    if (poolFloats > uint64_t(std::numeric_limits<int32_t>::max()) - 64)
        throw Error(path, "too many non-empty bricks for 32-bit offsets");
    resizeFreshHugePages(v.pool, size_t(poolFloats) * 4 + 64);
    float* pool = reinterpret_cast<float*>(v.pool.data());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, list.size()), [&](const tbb::blocked_range<size_t>& r) {
        auto acc = grid->getConstAccessor();
        for (size_t li = r.begin(); li != r.end(); ++li) {
            const size_t b = list[li];
            const int bx = int(b % size_t(v.nb[0])), by = int((b / size_t(v.nb[0])) % size_t(v.nb[1])),
                      bz = int(b / (size_t(v.nb[0]) * size_t(v.nb[1])));
            const int32_t start = int32_t((li + 1) * size_t(BrickedVolume::kBrick));
            float* dst = pool + start;
            int n = 0;
            for (int k = 0; k < BrickedVolume::kEdge; ++k)
                for (int j = 0; j < BrickedVolume::kEdge; ++j)
                    for (int i = 0; i < BrickedVolume::kEdge; ++i, ++n) {
                        // clamped at the grid's far faces, as brickVolume does for a dense
                        // grid: the brick's value range (which steers skipping and the step
                        // length) then matches the dense brick's
                        float s = acc.getValue(m0 + openvdb::Coord(std::min(bx * 8 + i, v.dims[0] - 1),
                                                                   std::min(by * 8 + j, v.dims[1] - 1),
                                                                   std::min(bz * 8 + k, v.dims[2] - 1)));
                        if (!std::isfinite(s)) s = 0.0f;
                        dst[n] = s;
                    }
            v.brickStart[b] = start;
            setBrickRanges(v, b, dst);
        }
    });
    return v;
}

}  // namespace rtfact::volume
