// PLY reading and writing. The header is parsed and every count checked against the
// file size before anything is allocated; binary bodies are decoded in parallel.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/memory_budget.h"
#include "points/huge_pages.h"
#include "points/point_cloud_io.h"
#include "points/point_cloud_io_detail.h"

namespace rtfact::points {
namespace detail {

MappedFile::MappedFile(const std::string& file) : name(file) {
    requireRegularFile(file);  // open() itself would block on a named pipe without a writer
    const int fd = ::open(file.c_str(), O_RDONLY);
    if (fd < 0) throw Error(file, std::string("cannot open: ") + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        throw Error(file, "not a regular file");
    }
    size = size_t(st.st_size);
    if (size > 0) {
        void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
        if (p == MAP_FAILED) {
            ::close(fd);
            throw Error(file, "cannot map file");
        }
        data = static_cast<const char*>(p);
    }
    ::close(fd);
}
MappedFile::~MappedFile() {
    if (data) ::munmap(const_cast<char*>(data), size);
}

int typeSize(ScalarType t) {
    switch (t) {
        case ScalarType::I8:
        case ScalarType::U8:
            return 1;
        case ScalarType::I16:
        case ScalarType::U16:
            return 2;
        case ScalarType::I32:
        case ScalarType::U32:
        case ScalarType::F32:
            return 4;
        case ScalarType::F64:
            return 8;
    }
    return 0;
}

std::optional<ScalarType> parseType(const std::string& s) {
    if (s == "char" || s == "int8") return ScalarType::I8;
    if (s == "uchar" || s == "uint8") return ScalarType::U8;
    if (s == "short" || s == "int16") return ScalarType::I16;
    if (s == "ushort" || s == "uint16") return ScalarType::U16;
    if (s == "int" || s == "int32") return ScalarType::I32;
    if (s == "uint" || s == "uint32") return ScalarType::U32;
    if (s == "float" || s == "float32") return ScalarType::F32;
    if (s == "double" || s == "float64") return ScalarType::F64;
    return std::nullopt;
}

double readScalar(const char* p, ScalarType t, bool bigEndian) {
    const int n = typeSize(t);
    uint64_t bits = 0;
    std::memcpy(&bits, p, size_t(n));
    // Swap in a register (std::reverse on the byte array draws a GCC 12 false warning).
    if (bigEndian) bits = __builtin_bswap64(bits) >> (64 - 8 * n);
    unsigned char b[8];
    std::memcpy(b, &bits, 8);
    switch (t) {
        case ScalarType::I8:
            return double(int8_t(b[0]));
        case ScalarType::U8:
            return double(b[0]);
        case ScalarType::I16: {
            int16_t v;
            std::memcpy(&v, b, 2);
            return v;
        }
        case ScalarType::U16: {
            uint16_t v;
            std::memcpy(&v, b, 2);
            return v;
        }
        case ScalarType::I32: {
            int32_t v;
            std::memcpy(&v, b, 4);
            return v;
        }
        case ScalarType::U32: {
            uint32_t v;
            std::memcpy(&v, b, 4);
            return v;
        }
        case ScalarType::F32: {
            float v;
            std::memcpy(&v, b, 4);
            return v;
        }
        case ScalarType::F64: {
            double v;
            std::memcpy(&v, b, 8);
            return v;
        }
    }
    return 0;
}

// Which per-point attribute a property name feeds.
Attr attrOf(const std::string& name) {
    static const std::pair<const char*, Attr> table[] = {
        {"x", Attr::X},
        {"y", Attr::Y},
        {"z", Attr::Z},
        {"nx", Attr::NX},
        {"ny", Attr::NY},
        {"nz", Attr::NZ},
        {"normal_x", Attr::NX},
        {"normal_y", Attr::NY},
        {"normal_z", Attr::NZ},
        {"red", Attr::R},
        {"green", Attr::G},
        {"blue", Attr::B},
        {"r", Attr::R},
        {"g", Attr::G},
        {"b", Attr::B},
        {"diffuse_red", Attr::R},
        {"diffuse_green", Attr::G},
        {"diffuse_blue", Attr::B},
        {"radius", Attr::Radius},
        {"scale", Attr::Radius},
        {"point_size", Attr::Radius},
        {"intensity", Attr::Intensity},
        {"scalar_intensity", Attr::Intensity},
    };
    for (const auto& [n, a] : table)
        if (name == n) return a;
    return Attr::None;
}

uint8_t colorByte(double v, ScalarType t) {
    if (t == ScalarType::F32 || t == ScalarType::F64)
        v *= 255.0;
    else if (t == ScalarType::U16)
        v /= 257.0;
    if (!(v > 0)) return 0;
    return uint8_t(std::min(255.0, std::round(v)));
}

// Collects one decoded point; finite check and origin shift happen in finish().
void PointSink::reserve(const std::string& file, size_t n, bool normals, bool colors, bool radius, bool intensity) {
    // Decoded (double positions) and final (float) copies live together in finish().
    const uint64_t perPoint = 24 + 12 + (normals ? 24 : 0) + (colors ? 6 : 0) + (radius ? 8 : 0) + (intensity ? 8 : 0);
    checkMemory(file, uint64_t(n) * perPoint, "loading " + std::to_string(n) + " points",
                "subsample the cloud, e.g. with pcl_voxel_grid");
    resizeHuge(pos, n);
    if (normals) resizeHuge(nrm, n);
    if (colors) resizeHuge(col, n);
    if (radius) resizeHuge(rad, n);
    if (intensity) resizeHuge(inten, n);
}

namespace {
// Coordinates beyond 1e18 are finite in double but overflow float arithmetic (squared
// distances) once converted: such points are dropped like NaN/inf ones.
constexpr double kMaxCoordinate = 1e18;
bool finite3(const std::array<double, 3>& p) {
    return std::fabs(p[0]) < kMaxCoordinate && std::fabs(p[1]) < kMaxCoordinate && std::fabs(p[2]) < kMaxCoordinate;
}
}  // namespace

void PointSink::finish(const std::string& file, PointCloud& out) {
    const size_t n = pos.size();
    // Origin shift in double so that large (UTM) coordinates keep their precision.
    for (size_t i = 0; i < n; ++i) {
        if (!finite3(pos[i])) continue;
        const auto& p = pos[i];
        if (std::max({std::fabs(p[0]), std::fabs(p[1]), std::fabs(p[2])}) > 1e4)
            out.origin = {std::round(p[0]), std::round(p[1]), std::round(p[2])};
        break;
    }
    // Destination slot of each kept point: per-block counts, then prefix sums, so that
    // the copy runs in parallel.
    const size_t block = 1 << 16, blocks = (n + block - 1) / block;
    std::vector<size_t> start(blocks + 1, 0);
    tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
        size_t c = 0;
        for (size_t i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i) c += finite3(pos[i]);
        start[b + 1] = c;
    });
    for (size_t b = 0; b < blocks; ++b) start[b + 1] += start[b];
    const size_t kept = start[blocks];
    out.droppedNonFinite = n - kept;
    if (kept == 0)
        throw Error(file,
                    n == 0 ? "empty point cloud" : "no point with finite coordinates (all NaN, inf or beyond 1e18)");
    resizeHuge(out.positions, kept);
    if (!nrm.empty()) resizeHuge(out.normals, kept);
    if (!col.empty()) out.colors.resize(kept);
    if (!rad.empty()) out.radii.resize(kept);
    if (!inten.empty()) out.intensities.resize(kept);
    const std::array<double, 3> o = out.origin;
    tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
        size_t k = start[b];
        for (size_t i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i) {
            const auto& p = pos[i];
            if (!finite3(p)) continue;
            out.positions[k] = Vec3f(float(p[0] - o[0]), float(p[1] - o[1]), float(p[2] - o[2]));
            if (!nrm.empty()) {
                const Vec3f v = nrm[i];
                const float l = length(v);
                out.normals[k] = std::isfinite(l) && l > 0 ? v * (1.0f / l) : Vec3f(0, 0, 0);
            }
            if (!col.empty()) out.colors[k] = col[i];
            if (!rad.empty()) out.radii[k] = std::isfinite(rad[i]) && rad[i] > 0 ? rad[i] : 0.0f;
            if (!inten.empty()) out.intensities[k] = std::isfinite(inten[i]) ? inten[i] : 0.0f;
            ++k;
        }
    });
    pos = {};
    nrm = {};
    col = {};
    rad = {};
    inten = {};
}

}  // namespace detail

using namespace detail;

namespace {

struct PlyProperty {
    std::string name;
    ScalarType type = ScalarType::F32;
    bool isList = false;
    ScalarType countType = ScalarType::U8;
};
struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> props;
};
enum class PlyFormat { Ascii, BinaryLE, BinaryBE };
struct PlyHeader {
    PlyFormat format = PlyFormat::Ascii;
    std::vector<PlyElement> elements;
    size_t bodyOffset = 0;
};

PlyHeader parsePlyHeader(const MappedFile& f) {
    const std::string& file = f.name;
    if (f.size < 4 || std::memcmp(f.data, "ply", 3) != 0 || (f.data[3] != '\n' && f.data[3] != '\r'))
        throw Error(file, "not a PLY file (missing 'ply' magic)");
    // The header is searched within its first 1 MiB only: a file without end_header there
    // is not read further (a hostile comment of megabytes would otherwise be parsed whole).
    constexpr size_t kMaxHeader = size_t(1) << 20;
    const size_t limit = std::min(f.size, kMaxHeader);
    const std::string_view head(f.data, limit);
    // end_header as a line of its own (not inside a comment).
    size_t end = 0;
    for (size_t from = 0;; from = end + 1) {
        end = head.find("end_header", from);
        if (end == std::string_view::npos) break;
        const size_t after = end + 10;
        const bool lineEnds = after >= head.size() || head[after] == '\n' || head[after] == '\r' || head[after] == ' ';
        if (end > 0 && head[end - 1] == '\n' && lineEnds) break;
    }
    const size_t body = end == std::string_view::npos ? end : head.find('\n', end);
    if (body == std::string_view::npos && f.size > kMaxHeader)
        throw Error(file, "PLY header longer than the 1 MiB limit (no end_header line in the first 1048576 bytes)");
    if (end == std::string_view::npos) throw Error(file, "PLY header has no end_header (truncated?)");
    if (body == std::string_view::npos) throw Error(file, "PLY header not terminated by a newline");
    PlyHeader h;
    h.bodyOffset = body + 1;
    std::istringstream in{std::string(head.substr(0, end))};
    std::string line;
    bool haveFormat = false;
    std::getline(in, line);  // "ply"
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream ls(line);
        std::string kw;
        ls >> kw;
        if (kw.empty() || kw == "comment" || kw == "obj_info") continue;
        if (kw == "format") {
            std::string fmt, ver;
            ls >> fmt >> ver;
            if (fmt == "ascii")
                h.format = PlyFormat::Ascii;
            else if (fmt == "binary_little_endian")
                h.format = PlyFormat::BinaryLE;
            else if (fmt == "binary_big_endian")
                h.format = PlyFormat::BinaryBE;
            else
                throw Error(file, "unknown PLY format '" + fmt + "'");
            haveFormat = true;
        } else if (kw == "element") {
            PlyElement e;
            std::string count;
            ls >> e.name >> count;
            if (count.empty() || count[0] == '-') throw Error(file, "bad count for element '" + e.name + "'");
            auto [p, ec] = std::from_chars(count.data(), count.data() + count.size(), e.count);
            if (ec != std::errc{} || p != count.data() + count.size())
                throw Error(file, "bad count '" + count + "' for element '" + e.name + "'");
            h.elements.push_back(e);
        } else if (kw == "property") {
            if (h.elements.empty()) throw Error(file, "PLY property before any element");
            PlyProperty p;
            std::string t;
            ls >> t;
            if (t == "list") {
                std::string ct, it;
                ls >> ct >> it >> p.name;
                auto c = parseType(ct), i = parseType(it);
                if (!c || !i) throw Error(file, "bad list property types in PLY header");
                p.isList = true;
                p.countType = *c;
                p.type = *i;
            } else {
                auto ty = parseType(t);
                if (!ty) throw Error(file, "unknown PLY property type '" + t + "'");
                p.type = *ty;
                ls >> p.name;
            }
            h.elements.back().props.push_back(p);
        } else {
            throw Error(file, "unexpected PLY header line '" + line + "'");
        }
    }
    if (!haveFormat) throw Error(file, "PLY header has no format line");
    return h;
}

const PlyElement* findElement(const PlyHeader& h, const std::string& name) {
    for (const auto& e : h.elements)
        if (e.name == name) return &e;
    return nullptr;
}

// Ascii token reader over the mapped body.
struct Tokens {
    const char* p;
    const char* end;
    bool next(std::string_view& tok) {
        while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) ++p;
        if (p >= end) return false;
        const char* s = p;
        while (p < end && !(*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) ++p;
        tok = {s, size_t(p - s)};
        return true;
    }
    double number(const std::string& file) {
        std::string_view t;
        if (!next(t)) throw Error(file, "PLY body truncated: fewer values than the header declares");
        double v;
        auto [q, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (ec != std::errc{} || q != t.data() + t.size()) {
            // from_chars rejects "nan"/"inf" spellings of some writers: treat as NaN.
            if (t == "nan" || t == "-nan" || t == "NaN" || t == "inf" || t == "-inf") return std::nan("");
            throw Error(file, "bad number '" + std::string(t.substr(0, 32)) + "' in PLY body");
        }
        return v;
    }
};

// Bytes one binary element occupies when it has no list properties, else 0.
size_t fixedSize(const PlyElement& e) {
    size_t s = 0;
    for (const auto& p : e.props) {
        if (p.isList) return 0;
        s += size_t(typeSize(p.type));
    }
    return s;
}

// Skips `e` in a binary body, walking lists; throws when the body ends early.
size_t skipBinary(const MappedFile& f, size_t off, const PlyElement& e, bool be) {
    const size_t fs = fixedSize(e);
    if (fs > 0) {
        if (e.count > (f.size - off) / fs)
            throw Error(f.name, "PLY element '" + e.name + "' runs past the end of the file");
        return off + fs * e.count;
    }
    for (uint64_t i = 0; i < e.count; ++i) {
        for (const auto& p : e.props) {
            if (!p.isList) {
                off += size_t(typeSize(p.type));
                if (off > f.size) throw Error(f.name, "PLY body truncated in element '" + e.name + "'");
                continue;
            }
            const size_t cs = size_t(typeSize(p.countType));
            if (off + cs > f.size) throw Error(f.name, "PLY body truncated in element '" + e.name + "'");
            const double c = readScalar(f.data + off, p.countType, be);
            off += cs;
            if (!(c >= 0) || c * typeSize(p.type) > double(f.size - off))
                throw Error(f.name, "PLY list in element '" + e.name + "' runs past the end of the file");
            off += size_t(c) * size_t(typeSize(p.type));
        }
    }
    return off;
}

}  // namespace

std::optional<PointFileInfo> probePly(const std::string& file) {
    MappedFile f(file);
    const PlyHeader h = parsePlyHeader(f);
    const PlyElement* v = findElement(h, "vertex");
    const PlyElement* faces = findElement(h, "face");
    if (!v || (faces && faces->count > 0)) return std::nullopt;
    PointFileInfo info;
    info.format = h.format == PlyFormat::Ascii      ? "ply ascii"
                  : h.format == PlyFormat::BinaryLE ? "ply binary_little_endian"
                                                    : "ply binary_big_endian";
    info.points = v->count;
    for (const auto& p : v->props) info.properties.push_back(p.name);
    return info;
}

void detail::storeAttr(PointSink& sink, size_t i, Attr a, double x, ScalarType type, bool hasN, bool hasC) {
    switch (a) {
        case Attr::X:
            sink.pos[i][0] = x;
            break;
        case Attr::Y:
            sink.pos[i][1] = x;
            break;
        case Attr::Z:
            sink.pos[i][2] = x;
            break;
        case Attr::NX:
            if (hasN) sink.nrm[i].x = float(x);
            break;
        case Attr::NY:
            if (hasN) sink.nrm[i].y = float(x);
            break;
        case Attr::NZ:
            if (hasN) sink.nrm[i].z = float(x);
            break;
        case Attr::R:
            if (hasC) sink.col[i][0] = colorByte(x, type);
            break;
        case Attr::G:
            if (hasC) sink.col[i][1] = colorByte(x, type);
            break;
        case Attr::B:
            if (hasC) sink.col[i][2] = colorByte(x, type);
            break;
        case Attr::Radius:
            sink.rad[i] = float(x);
            break;
        case Attr::Intensity:
            sink.inten[i] = float(x);
            break;
        default:
            break;
    }
}

PointCloud loadPly(const std::string& file) {
    MappedFile f(file);
    const PlyHeader h = parsePlyHeader(f);
    const PlyElement* v = findElement(h, "vertex");
    if (!v) throw Error(file, "PLY file has no vertex element");
    if (v->count == 0) throw Error(file, "empty point cloud (0 vertices)");
    const bool be = h.format == PlyFormat::BinaryBE;
    // Property slots per attribute.
    struct Slot {
        Attr attr;
        ScalarType type;
        size_t offset;
    };
    std::vector<Slot> slots;
    bool has[int(Attr::Count)] = {};
    size_t off = 0;
    for (const auto& p : v->props) {
        if (p.isList) {
            if (h.format != PlyFormat::Ascii)
                throw Error(file, "list properties in the vertex element are not supported");
        } else {
            const Attr a = attrOf(p.name);
            if (a != Attr::None && !has[int(a)]) {
                slots.push_back({a, p.type, off});
                has[int(a)] = true;
            }
            off += size_t(typeSize(p.type));
        }
    }
    if (!has[int(Attr::X)] || !has[int(Attr::Y)] || !has[int(Attr::Z)])
        throw Error(file, "PLY vertices lack x, y or z");
    PointCloud cloud;
    cloud.format = h.format == PlyFormat::Ascii ? "ply ascii"
                   : be                         ? "ply binary_big_endian"
                                                : "ply binary_little_endian";
    for (const auto& p : v->props) cloud.properties.push_back(p.name);
    const bool hasN = has[int(Attr::NX)] && has[int(Attr::NY)] && has[int(Attr::NZ)];
    const bool hasC = has[int(Attr::R)] && has[int(Attr::G)] && has[int(Attr::B)];
    PointSink sink;
    const size_t n = size_t(v->count);

    if (h.format == PlyFormat::Ascii) {
        // Each value takes at least two bytes ("0 "): a cheap bound before allocating.
        const size_t remaining = f.size - h.bodyOffset;
        if (v->count > remaining / std::max<size_t>(2 * v->props.size(), 2))
            throw Error(file,
                        "PLY header declares " + std::to_string(v->count) + " vertices but the file is too small");
        Tokens tk{f.data + h.bodyOffset, f.data + f.size};
        for (const auto& e : h.elements) {
            if (&e == v) break;
            if (e.count > remaining / 2) throw Error(file, "PLY element '" + e.name + "' count exceeds the file size");
            for (uint64_t i = 0; i < e.count; ++i)
                for (const auto& p : e.props) {
                    if (!p.isList) {
                        tk.number(file);
                        continue;
                    }
                    const double c = tk.number(file);
                    if (!(c >= 0) || c > double(remaining)) throw Error(file, "bad list length in PLY body");
                    for (size_t j = 0; j < size_t(c); ++j) tk.number(file);
                }
        }
        sink.reserve(file, n, hasN, hasC, has[int(Attr::Radius)], has[int(Attr::Intensity)]);
        std::vector<double> vals(v->props.size());
        for (size_t i = 0; i < n; ++i) {
            size_t slot = 0;
            for (size_t pi = 0; pi < v->props.size(); ++pi) {
                const auto& p = v->props[pi];
                if (p.isList) {
                    const double c = tk.number(file);
                    if (!(c >= 0) || c > double(remaining)) throw Error(file, "bad list length in PLY body");
                    for (size_t j = 0; j < size_t(c); ++j) tk.number(file);
                    continue;
                }
                vals[slot++] = tk.number(file);
            }
            // Map values (in scalar property order) to attributes.
            size_t s = 0;
            for (const auto& p : v->props) {
                if (p.isList) continue;
                const double x = vals[s++];
                storeAttr(sink, i, attrOf(p.name), x, p.type, hasN, hasC);
            }
        }
    } else {
        size_t pos = h.bodyOffset;
        for (const auto& e : h.elements) {
            if (&e == v) break;
            pos = skipBinary(f, pos, e, be);
        }
        const size_t stride = fixedSize(*v);
        if (stride == 0) throw Error(file, "PLY vertex element has no fixed-size layout");
        if (v->count > (f.size - pos) / stride)
            throw Error(file, "PLY header declares " + std::to_string(v->count) + " vertices (" +
                                  std::to_string(v->count * stride) + " bytes) but only " +
                                  std::to_string(f.size - pos) +
                                  " bytes follow the header (truncated or lying header)");
        sink.reserve(file, n, hasN, hasC, has[int(Attr::Radius)], has[int(Attr::Intensity)]);
        const char* base = f.data + pos;
        // Fast path: little-endian float x,y,z.
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i < r.end(); ++i) {
                const char* rec = base + i * stride;
                for (const Slot& s : slots) {
                    double x;
                    if (s.type == ScalarType::F32 && !be) {
                        float fv;
                        std::memcpy(&fv, rec + s.offset, 4);
                        x = fv;
                    } else {
                        x = readScalar(rec + s.offset, s.type, be);
                    }
                    storeAttr(sink, i, s.attr, x, s.type, hasN, hasC);
                }
            }
        });
    }
    sink.finish(file, cloud);
    return cloud;
}

void writePly(const std::string& file, const PointCloud& c) {
    const bool hasN = c.normals.size() == c.size(), hasC = c.colors.size() == c.size(),
               hasR = c.radii.size() == c.size();
    const std::string tmp = file + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) throw Error(file, "cannot write");
        out << "ply\nformat binary_little_endian 1.0\ncomment written by rtfact\nelement vertex " << c.size()
            << "\nproperty float x\nproperty float y\nproperty float z\n";
        if (hasN) out << "property float nx\nproperty float ny\nproperty float nz\n";
        if (hasC) out << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
        if (hasR) out << "property float radius\n";
        out << "end_header\n";
        std::vector<char> buf;
        const size_t stride = 12 + (hasN ? 12 : 0) + (hasC ? 3 : 0) + (hasR ? 4 : 0);
        const size_t block = 1 << 16;
        buf.resize(stride * block);
        for (size_t b = 0; b < c.size(); b += block) {
            const size_t e = std::min(c.size(), b + block);
            char* p = buf.data();
            for (size_t i = b; i < e; ++i) {
                std::memcpy(p, &c.positions[i], 12), p += 12;
                if (hasN) std::memcpy(p, &c.normals[i], 12), p += 12;
                if (hasC) std::memcpy(p, c.colors[i].data(), 3), p += 3;
                if (hasR) std::memcpy(p, &c.radii[i], 4), p += 4;
            }
            out.write(buf.data(), std::streamsize(p - buf.data()));
        }
        if (!out) throw Error(file, "write failed");
    }
    std::error_code ec;
    std::filesystem::rename(tmp, file, ec);
    if (ec) throw Error(file, "cannot rename temporary file: " + ec.message());
}

TriangleMesh loadPlyMesh(const std::string& file) {
    MappedFile f(file);
    const PlyHeader h = parsePlyHeader(f);
    const PlyElement* v = findElement(h, "vertex");
    const PlyElement* fe = findElement(h, "face");
    if (!v || !fe || fe->count == 0) throw Error(file, "PLY file has no faces (not a mesh)");
    PointCloud pts = loadPly(file);  // validated vertex positions (no NaN dropping for meshes with NaNs)
    if (pts.droppedNonFinite) throw Error(file, "mesh has vertices with non-finite coordinates");
    TriangleMesh m;
    m.vertices = std::move(pts.positions);
    const bool be = h.format == PlyFormat::BinaryBE;
    const size_t remaining = f.size - h.bodyOffset;
    if (fe->count > remaining / 2) throw Error(file, "PLY face count exceeds the file size");
    int listIdx = -1;
    for (size_t i = 0; i < fe->props.size(); ++i)
        if (fe->props[i].isList && (fe->props[i].name == "vertex_indices" || fe->props[i].name == "vertex_index"))
            listIdx = int(i);
    if (listIdx < 0) throw Error(file, "PLY faces have no vertex_indices list");
    m.triangles.reserve(size_t(fe->count));
    auto addPoly = [&](const std::vector<double>& idx) {
        for (double d : idx)
            if (!(d >= 0 && d < double(m.vertices.size()))) throw Error(file, "face index out of range");
        for (size_t j = 2; j < idx.size(); ++j)
            m.triangles.push_back({uint32_t(idx[0]), uint32_t(idx[j - 1]), uint32_t(idx[j])});
    };
    std::vector<double> idx;
    if (h.format == PlyFormat::Ascii) {
        Tokens tk{f.data + h.bodyOffset, f.data + f.size};
        for (const auto& e : h.elements) {
            const bool isFace = &e == fe;
            for (uint64_t i = 0; i < e.count; ++i)
                for (size_t pi = 0; pi < e.props.size(); ++pi) {
                    const auto& p = e.props[pi];
                    if (!p.isList) {
                        tk.number(file);
                        continue;
                    }
                    const double c = tk.number(file);
                    if (!(c >= 0) || c > double(remaining)) throw Error(file, "bad list length in PLY body");
                    idx.clear();
                    for (size_t j = 0; j < size_t(c); ++j) idx.push_back(tk.number(file));
                    if (isFace && int(pi) == listIdx) addPoly(idx);
                }
            if (isFace) break;
        }
    } else {
        size_t pos = h.bodyOffset;
        for (const auto& e : h.elements) {
            if (&e == fe) break;
            pos = skipBinary(f, pos, e, be);
        }
        for (uint64_t i = 0; i < fe->count; ++i)
            for (size_t pi = 0; pi < fe->props.size(); ++pi) {
                const auto& p = fe->props[pi];
                if (!p.isList) {
                    pos += size_t(typeSize(p.type));
                    if (pos > f.size) throw Error(file, "PLY face data truncated");
                    continue;
                }
                const size_t cs = size_t(typeSize(p.countType));
                if (pos + cs > f.size) throw Error(file, "PLY face data truncated");
                const double c = readScalar(f.data + pos, p.countType, be);
                pos += cs;
                const size_t is = size_t(typeSize(p.type));
                if (!(c >= 0) || c * double(is) > double(f.size - pos)) throw Error(file, "PLY face data truncated");
                idx.clear();
                for (size_t j = 0; j < size_t(c); ++j) idx.push_back(readScalar(f.data + pos + j * is, p.type, be));
                pos += size_t(c) * is;
                if (int(pi) == listIdx) addPoly(idx);
            }
    }
    if (m.triangles.empty()) throw Error(file, "mesh has no triangles");
    return m;
}

}  // namespace rtfact::points
