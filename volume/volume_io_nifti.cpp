// NIfTI-1 (.nii, .nii.gz).
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/io/byte_stream.h"
#include "core/io/file_helpers.h"
#include "core/io/scalar_type.h"
#include "core/util/error.h"
#include "volume/volume_io.h"
#include "volume/volume_io_detail.h"

namespace rtfact::volume {

using namespace detail;
using io::endsWith;
using io::fileSize;
using io::lower;
using io::ScalarType;

VolumeGrid loadNifti(const std::string& path, const VolumeLoadOptions& o) {
    const bool gz = endsWith(lower(path), ".gz");
    const uint64_t fsz = fileSize(path);
    uint8_t h[348];
    {
        io::ByteStream s(path, 0, gz);
        s.read(h, sizeof(h), "NIfTI header");
    }
    int32_t sz;
    std::memcpy(&sz, h, 4);
    bool swap = false;
    if (sz != 348) {
        swap = true;
        sz = io::loadScalar<int32_t>(h, true);
        if (sz != 348) throw Error(path, "not a NIfTI-1 file (sizeof_hdr is not 348)");
    }
    if (std::memcmp(h + 344, "n+1", 4) != 0)
        throw Error(path, std::memcmp(h + 344, "ni1", 4) == 0
                              ? "NIfTI .hdr/.img pairs are not supported; use a single .nii"
                              : "bad NIfTI magic (expected n+1)");
    auto i16 = [&](int off) { return io::loadScalar<int16_t>(h + off, swap); };
    auto f32 = [&](int off) { return io::loadScalar<float>(h + off, swap); };
    const int nd = i16(40);
    if (nd < 1 || nd > 7) throw Error(path, "bad NIfTI dim[0] = " + std::to_string(nd));
    std::vector<int64_t> d = {1, 1, 1};
    for (int a = 0; a < nd; ++a) {
        const int64_t v = i16(42 + 2 * a);
        if (a < 3)
            d[size_t(a)] = v;
        else if (v > 1)
            throw Error(path, "NIfTI with " + std::to_string(nd) + " dimensions (dim[" + std::to_string(a + 1) +
                                  "] = " + std::to_string(v) + "): only 3D volumes are supported");
    }
    VolumeGrid g;
    setDims(g, path, d);
    const int dt = i16(70);
    ScalarType src;
    switch (dt) {
        case 2:
            src = ScalarType::U8;
            break;
        case 4:
            src = ScalarType::I16;
            break;
        case 8:
            src = ScalarType::I32;
            break;
        case 16:
            src = ScalarType::F32;
            break;
        case 64:
            src = ScalarType::F64;
            break;
        case 256:
            src = ScalarType::I8;
            break;
        case 512:
            src = ScalarType::U16;
            break;
        case 768:
            src = ScalarType::U32;
            break;
        default:
            throw Error(path, "unsupported NIfTI datatype " + std::to_string(dt));
    }
    std::vector<double> sp;
    for (int a = 0; a < 3; ++a) {
        const float v = std::fabs(f32(80 + 4 * a));
        sp.push_back(v > 0 && std::isfinite(v) ? v : 1.0);
    }
    setSpacing(g, path, sp);
    const float vox = f32(108);
    if (!std::isfinite(vox) || vox < 348 || vox > float(fsz) * 1100.0f) throw Error(path, "bad NIfTI vox_offset");
    // NIfTI has no modality field; its free-text descrip or aux_file may name one.
    if (const std::string w = modalityWord(headerText(h + 148, 80)); !w.empty())
        g.meta = {w, "NIfTI descrip"};
    else if (const std::string a = modalityWord(headerText(h + 228, 24)); !a.empty())
        g.meta = {a, "NIfTI aux_file"};
    const float slope = f32(112), inter = f32(116);
    if (std::isfinite(slope) && slope != 0.0f) {
        g.scale = slope;
        g.offset = std::isfinite(inter) ? inter : 0.0f;
    }
    const uint64_t bytes = g.voxelCount() * uint64_t(io::scalarBytes(src));
    std::vector<Piece> pieces;
    if (gz)
        pieces.push_back({path, 0, uint64_t(vox), true, bytes});
    else
        pieces.push_back({path, uint64_t(vox), 0, false, bytes});
    decodePayload(g, src, swap, pieces, path, o);
    return g;
}

}  // namespace rtfact::volume
