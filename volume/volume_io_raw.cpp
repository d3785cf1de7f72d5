// Raw voxel files: dims and type from the options or from an Open SciVis style name
// (name_XxYxZ_type.raw).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/io/file_helpers.h"
#include "core/io/scalar_type.h"
#include "core/util/error.h"
#include "volume/volume_io.h"
#include "volume/volume_io_detail.h"

namespace rtfact::volume {

namespace fs = std::filesystem;
using namespace detail;
using io::fileSize;
using io::lower;
using io::ScalarType;

VolumeGrid loadRaw(const std::string& path, const VolumeLoadOptions& o) {
    if (!o.dims) throw Error(path, "raw volume needs --dims X,Y,Z and --type u8|u16|i16|f32");
    if (o.type.empty()) throw Error(path, "raw volume needs --type u8|u16|i16|f32");
    VolumeGrid g;
    setDims(g, path, {(*o.dims)[0], (*o.dims)[1], (*o.dims)[2]});
    const ScalarType src = parseVoxelType(path, o.type);
    const uint64_t need = g.voxelCount() * uint64_t(io::scalarBytes(src));
    const uint64_t fsz = fileSize(path);
    if (fsz != o.headerSkip + need)
        throw Error(path,
                    "raw size mismatch: dims and type need " + std::to_string(need) + " bytes" +
                        (o.headerSkip ? " after a " + std::to_string(o.headerSkip) + "-byte header" : std::string()) +
                        ", file has " + std::to_string(fsz));
    std::vector<Piece> pieces{{path, o.headerSkip, 0, false, need}};
    decodePayload(g, src, lower(o.endian) == "big", pieces, path, o);
    return g;
}

void writeRaw(const std::string& path, const VolumeGrid& g) {
    std::ofstream f(path, std::ios::binary);
    if (!f) throw Error(path, "cannot write file");
    f.write(reinterpret_cast<const char*>(g.bytes.data()),
            std::streamsize(g.voxelCount() * size_t(storageBytes(g.storage))));
    if (!f) throw Error(path, "write failed");
}

VolumeLoadOptions rawOptionsFromName(const std::string& path, const VolumeLoadOptions& opt) {
    VolumeLoadOptions o = opt;
    const std::string stem = fs::path(path).stem().string();
    int x = 0, y = 0, z = 0;
    char type[32] = {};
    const size_t us = stem.find_last_of('_', stem.rfind('_') == std::string::npos ? 0 : stem.rfind('_') - 1);
    if (us != std::string::npos && std::sscanf(stem.c_str() + us + 1, "%dx%dx%d_%31s", &x, &y, &z, type) == 4) {
        o.dims = std::array<int, 3>{x, y, z};
        const std::string t = type;
        o.type = t == "uint8" ? "u8" : t == "uint16" ? "u16" : t == "int16" ? "i16" : t == "float32" ? "f32" : t;
    }
    return o;
}

}  // namespace rtfact::volume
