// Shared internals of the volume readers: voxel types and payload decoding, header text
// helpers. The gzip/zlib stream is core/io/byte_stream.h.
#include "volume/volume_io_detail.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "core/io/byte_stream.h"
#include "core/io/file_helpers.h"
#include "core/io/scalar_type.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/memory_budget.h"
#include "core/util/progress.h"

namespace rtfact::volume::detail {

using io::fileSize;
using io::lower;
using io::ScalarType;

namespace {

// Before allocating: can the pieces' files hold what the header claims?
void checkPieces(const std::string& header, std::vector<Piece>& pieces) {
    for (Piece& p : pieces) {
        const uint64_t fsz = fileSize(p.path);
        if (p.skipFromEnd && !p.compressed) {
            if (fsz < p.bytes)
                throw Error(p.path, "data file holds " + std::to_string(fsz) + " bytes, header needs " +
                                        std::to_string(p.bytes));
            p.offset = fsz - p.bytes;
            p.skip = 0;
        }
        if (p.offset > fsz)
            throw Error(p.path, "data offset " + std::to_string(p.offset) + " is beyond the end of the file (" +
                                    std::to_string(fsz) + " bytes)");
        const uint64_t avail = fsz - p.offset;
        if (!p.compressed) {
            if (avail < p.skip + p.bytes)
                throw Error(p.path, "size mismatch: header " +
                                        (header == p.path ? std::string() : "(" + header + ") ") + "needs " +
                                        std::to_string(p.skip + p.bytes) + " bytes of data, file has " +
                                        std::to_string(avail));
        } else {
            // deflate cannot compress better than about 1032:1
            const double maxOut = double(avail) * 1032.0 + 65536.0;
            if (double(p.skip + p.bytes) > maxOut)
                throw Error(p.path, "header claims " + std::to_string(p.skip + p.bytes) + " decompressed bytes, but " +
                                        std::to_string(avail) + " compressed bytes cannot hold that many");
        }
    }
}

Storage storageFor(ScalarType s) {
    switch (s) {
        case ScalarType::U8:
        case ScalarType::I8:
            return Storage::U8;
        case ScalarType::U16:
        case ScalarType::I16:
            return Storage::U16;
        default:
            return Storage::F32;
    }
}

}  // namespace

// Reads the pieces and converts the source type into the grid's compact storage.
void decodePayload(VolumeGrid& g, ScalarType src, bool bigEndian, std::vector<Piece>& pieces, const std::string& header,
                   const VolumeLoadOptions& o) {
    const bool progress = o.progress;
    uint64_t n = g.voxelCount();
    const int sb = io::scalarBytes(src);
    uint64_t total = 0;
    for (const Piece& p : pieces) total += p.bytes;
    if (total != n * uint64_t(sb))
        throw Error(header, "data pieces hold " + std::to_string(total) + " bytes, expected " +
                                std::to_string(n * uint64_t(sb)));
    if (o.slices) {  // a data-parallel rank's slab (docs/mpi.md)
        keepSlices(g, sb, pieces, header, o.slices({g.dims[0], g.dims[1], g.dims[2]}));
        n = g.voxelCount();
        total = n * uint64_t(sb);
    }
    checkPieces(header, pieces);
    g.sourceType = io::scalarTypeName(src);
    // The dense grid plus its bricked copy for rendering.
    checkMemory(header, n * uint64_t(storageBytes(storageFor(src))) * 2, "the volume",
                "a sparse OpenVDB grid renders without densifying");
    g.allocate(storageFor(src));
    const bool swap = bigEndian && sb > 1;
    std::vector<uint8_t> buf(size_t(1) << 20);
    uint64_t voxel = 0;
    Progress prog("load", total, progress);
    for (const Piece& p : pieces) {
        io::ByteStream s(p.path, p.offset, p.compressed);
        if (p.skip) s.skip(p.skip, "header bytes");
        uint64_t left = p.bytes;
        while (left > 0) {
            const size_t k = size_t(std::min<uint64_t>(left, buf.size()));
            s.read(buf.data(), k, "voxel data");
            const size_t cnt = k / size_t(sb);
            const uint8_t* b = buf.data();
            switch (src) {
                case ScalarType::U8:
                    std::memcpy(g.bytes.data() + voxel, b, cnt);
                    break;
                case ScalarType::I8:
                    for (size_t i = 0; i < cnt; ++i) g.bytes[voxel + i] = uint8_t(b[i] ^ 0x80);
                    break;
                case ScalarType::U16: {
                    uint16_t* d = g.data<uint16_t>() + voxel;
                    for (size_t i = 0; i < cnt; ++i) d[i] = io::loadScalar<uint16_t>(b + 2 * i, swap);
                    break;
                }
                case ScalarType::I16: {
                    uint16_t* d = g.data<uint16_t>() + voxel;
                    for (size_t i = 0; i < cnt; ++i)
                        d[i] = uint16_t(io::loadScalar<uint16_t>(b + 2 * i, swap) ^ 0x8000u);
                    break;
                }
                default: {
                    float* d = g.data<float>() + voxel;
                    for (size_t i = 0; i < cnt; ++i) {
                        const uint8_t* q = b + size_t(sb) * i;
                        float v;
                        if (src == ScalarType::U32)
                            v = float(io::loadScalar<uint32_t>(q, swap));
                        else if (src == ScalarType::I32)
                            v = float(io::loadScalar<int32_t>(q, swap));
                        else if (src == ScalarType::F32)
                            v = io::loadScalar<float>(q, swap);
                        else
                            v = float(io::loadScalar<double>(q, swap));
                        d[i] = std::isfinite(v) ? v : 0.0f;  // NaN/inf voxels read as 0
                    }
                }
            }
            voxel += cnt;
            left -= k;
            prog.add(k);
        }
        s.finish();
    }
    prog.finish();
    // Signed types live shifted in unsigned storage.
    if (src == ScalarType::I8) g.offset += -128.0f * g.scale;
    if (src == ScalarType::I16) g.offset += -32768.0f * g.scale;
}

ScalarType parseVoxelType(const std::string& file, std::string t) {
    t = lower(trim(t));
    static const std::map<std::string, ScalarType> m = {{"u8", ScalarType::U8},
                                                        {"uint8", ScalarType::U8},
                                                        {"uchar", ScalarType::U8},
                                                        {"unsigned char", ScalarType::U8},
                                                        {"uint8_t", ScalarType::U8},
                                                        {"met_uchar", ScalarType::U8},
                                                        {"i8", ScalarType::I8},
                                                        {"int8", ScalarType::I8},
                                                        {"signed char", ScalarType::I8},
                                                        {"int8_t", ScalarType::I8},
                                                        {"met_char", ScalarType::I8},
                                                        {"char", ScalarType::I8},
                                                        {"u16", ScalarType::U16},
                                                        {"uint16", ScalarType::U16},
                                                        {"ushort", ScalarType::U16},
                                                        {"unsigned short", ScalarType::U16},
                                                        {"unsigned short int", ScalarType::U16},
                                                        {"uint16_t", ScalarType::U16},
                                                        {"met_ushort", ScalarType::U16},
                                                        {"i16", ScalarType::I16},
                                                        {"int16", ScalarType::I16},
                                                        {"short", ScalarType::I16},
                                                        {"short int", ScalarType::I16},
                                                        {"signed short", ScalarType::I16},
                                                        {"signed short int", ScalarType::I16},
                                                        {"int16_t", ScalarType::I16},
                                                        {"met_short", ScalarType::I16},
                                                        {"u32", ScalarType::U32},
                                                        {"uint", ScalarType::U32},
                                                        {"unsigned int", ScalarType::U32},
                                                        {"uint32", ScalarType::U32},
                                                        {"uint32_t", ScalarType::U32},
                                                        {"met_uint", ScalarType::U32},
                                                        {"i32", ScalarType::I32},
                                                        {"int", ScalarType::I32},
                                                        {"signed int", ScalarType::I32},
                                                        {"int32", ScalarType::I32},
                                                        {"int32_t", ScalarType::I32},
                                                        {"met_int", ScalarType::I32},
                                                        {"f32", ScalarType::F32},
                                                        {"float", ScalarType::F32},
                                                        {"float32", ScalarType::F32},
                                                        {"met_float", ScalarType::F32},
                                                        {"f64", ScalarType::F64},
                                                        {"double", ScalarType::F64},
                                                        {"float64", ScalarType::F64},
                                                        {"met_double", ScalarType::F64}};
    auto it = m.find(t);
    if (it == m.end()) throw Error(file, "unsupported voxel type '" + t + "'");
    return it->second;
}

std::vector<std::string> splitWords(const std::string& s) {
    std::istringstream is(s);
    std::vector<std::string> w;
    std::string x;
    while (is >> x) w.push_back(x);
    return w;
}
double parseNumber(const std::string& file, const std::string& s, const std::string& what) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end == s.c_str() || *end != '\0' || !std::isfinite(v))
        throw Error(file, "bad " + what + " '" + s + "'");
    return v;
}

void setDims(VolumeGrid& g, const std::string& file, const std::vector<int64_t>& d) {
    if (d.size() != 3) throw Error(file, "expected 3 dimensions, got " + std::to_string(d.size()));
    int64_t dd[3] = {d[0], d[1], d[2]};
    checkedVoxelCount(file, dd);
    for (int a = 0; a < 3; ++a) g.dims[a] = int(dd[a]);
}
void setSpacing(VolumeGrid& g, const std::string& file, const std::vector<double>& s) {
    for (int a = 0; a < 3 && a < int(s.size()); ++a) {
        if (!(s[a] > 0) || !std::isfinite(s[a])) throw Error(file, "spacing must be positive and finite");
        g.spacing[a] = float(s[a]);
    }
}

// Reads a text header up to (not including) the first blank line or `limit` bytes.
std::string readTextHead(const std::string& path, size_t limit) {
    requireRegularFile(path);
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error(path, "cannot open file");
    std::string s(limit, '\0');
    f.read(s.data(), std::streamsize(limit));
    s.resize(size_t(f.gcount()));
    return s;
}

// A modality value as DICOM spells it: "MET_MOD_CT" (MetaImage), "ct", "MR" -> "CT", "MR".
std::string modalityTerm(std::string v) {
    v = trim(v);
    for (char& c : v) c = char(std::toupper((unsigned char)c));
    if (v.rfind("MET_MOD_", 0) == 0) v = v.substr(8);
    if (v == "MRI") v = "MR";
    if (v == "PET") v = "PT";
    if (v.empty() || v == "OTHER" || v == "UNKNOWN" || v.size() > 16) return "";
    for (char c : v)
        if (!std::isalnum((unsigned char)c)) return "";
    return v;
}
// "CT" or "MR" when free text names the modality as a word ("CT scan of a bonsai tree").
std::string modalityWord(const std::string& text) {
    std::string word;
    for (size_t i = 0; i <= text.size(); ++i) {
        const char c = i < text.size() ? text[i] : ' ';
        if (std::isalnum((unsigned char)c)) {
            word.push_back(c);
            continue;
        }
        if (word == "CT" || word == "MR" || word == "MRI") return word == "CT" ? "CT" : "MR";
        word.clear();
    }
    return "";
}
// Free text from a fixed-size, NUL-padded header field.
std::string headerText(const uint8_t* p, size_t n) {
    std::string s(reinterpret_cast<const char*>(p), n);
    return s.substr(0, s.find('\0'));
}

std::string trim(const std::string& s) {
    size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

}  // namespace rtfact::volume::detail

namespace rtfact::volume {

using namespace detail;

uint64_t checkedVoxelCount(const std::string& file, const int64_t dims[3]) {
    uint64_t n = 1;
    for (int a = 0; a < 3; ++a) {
        if (dims[a] <= 0)
            throw Error(file, "bad dimensions " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                                  std::to_string(dims[2]) + ": every size must be positive");
        if (uint64_t(dims[a]) > kMaxVoxels || __builtin_mul_overflow(n, uint64_t(dims[a]), &n) || n > kMaxVoxels)
            throw Error(file, "dimensions " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                                  std::to_string(dims[2]) + " are too large (at most 2^31-1 voxels are supported)");
    }
    return n;
}

std::array<int, 3> parseDims(const std::string& text) {
    std::string t = text;
    std::replace(t.begin(), t.end(), 'x', ',');
    std::replace(t.begin(), t.end(), ',', ' ');
    auto w = splitWords(t);
    if (w.size() != 3) throw Error("--dims", "expected X,Y,Z, got '" + text + "'");
    int64_t d[3];
    for (int a = 0; a < 3; ++a) {
        const double v = parseNumber("--dims", w[size_t(a)], "size");
        if (v != std::floor(v) || std::fabs(v) > 1e12) throw Error("--dims", "bad size '" + w[size_t(a)] + "'");
        d[a] = int64_t(v);
    }
    checkedVoxelCount("--dims", d);
    return {int(d[0]), int(d[1]), int(d[2])};
}

Vec3f parseSpacing(const std::string& text) {
    std::string t = text;
    std::replace(t.begin(), t.end(), ',', ' ');
    auto w = splitWords(t);
    if (w.size() != 3) throw Error("--spacing", "expected sx,sy,sz, got '" + text + "'");
    Vec3f s;
    for (int a = 0; a < 3; ++a) {
        s[a] = float(parseNumber("--spacing", w[size_t(a)], "spacing"));
        if (!(s[a] > 0)) throw Error("--spacing", "spacing must be positive");
    }
    return s;
}

}  // namespace rtfact::volume
