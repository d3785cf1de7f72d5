// OpenVDB grids: the named (or first) float grid, densified over its active bounding box.
// OpenVDB headers stay in this file (and in the benchmark).
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <cmath>

#include "core/util/error.h"
#include "volume/volume_io.h"

namespace rtfact::volume {

VolumeGrid loadVDB(const std::string& path, const VolumeLoadOptions& opt) {
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid;
    std::string name;
    try {
        openvdb::io::File file(path);
        file.open(false);  // no delayed loading: corrupt files fail here, not later
        openvdb::GridPtrVecPtr metas = file.readAllGridMetadata();
        for (auto& m : *metas) {
            if (!opt.grid.empty() && m->getName() != opt.grid) continue;
            if (m->valueType() != "float") {
                if (!opt.grid.empty()) throw Error(path, "grid '" + opt.grid + "' holds " + m->valueType() + " values, not float");
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
        throw Error(path, std::string("cannot read OpenVDB file: ") + e.what());
    }
    if (!grid) throw Error(path, "grid '" + name + "' is not a float grid");
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
