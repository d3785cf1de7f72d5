// PLY reading and writing, and the point sink shared with the PCD and XYZ readers. The
// header (core/io/ply_header.h) checks every count against the file size before anything
// is allocated; binary bodies are decoded in parallel.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/io/ply_header.h"
#include "core/util/error.h"
#include "core/util/huge_pages.h"
#include "core/util/memory_budget.h"
#include "points/point_cloud_io.h"
#include "points/point_cloud_io_detail.h"

namespace rtfact::points {
namespace detail {

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

bool scalarAttribute(const std::string& name) {
    return name.rfind("scalar_", 0) == 0 || name == "class" || name == "classification" || name == "label";
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
    const uint64_t perPoint =
        24 + 12 + (normals ? 24 : 0) + (colors ? 6 : 0) + (radius ? 8 : 0) + (intensity ? 8 : 0) + 8 * scalars.size();
    checkMemory(file, uint64_t(n) * perPoint, "loading " + std::to_string(n) + " points",
                "subsample the cloud, e.g. with pcl_voxel_grid");
    resizeHugePages(pos, n);
    if (normals) resizeHugePages(nrm, n);
    if (colors) resizeHugePages(col, n);
    if (radius) resizeHugePages(rad, n);
    if (intensity) resizeHugePages(inten, n);
    for (ScalarField& f : scalars) f.values.resize(n);
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
    resizeHugePages(out.positions, kept);
    if (!nrm.empty()) resizeHugePages(out.normals, kept);
    if (!col.empty()) out.colors.resize(kept);
    if (!rad.empty()) out.radii.resize(kept);
    if (!inten.empty()) out.intensities.resize(kept);
    out.scalars.resize(scalars.size());
    for (size_t a = 0; a < scalars.size(); ++a) {
        out.scalars[a].name = scalars[a].name;
        out.scalars[a].values.resize(kept);
    }
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
            for (size_t a = 0; a < scalars.size(); ++a) out.scalars[a].values[k] = scalars[a].values[i];
            ++k;
        }
    });
    pos = {};
    nrm = {};
    col = {};
    rad = {};
    inten = {};
    scalars = {};
    // A class/classification/label field is the classification too (colour, --classes).
    for (const ScalarField& f : out.scalars)
        if (f.name == "class" || f.name == "classification" || f.name == "label") {
            out.classes.resize(kept);
            for (size_t i = 0; i < kept; ++i)
                out.classes[i] = uint8_t(std::clamp(std::isfinite(f.values[i]) ? f.values[i] : 0.0f, 0.0f, 255.0f));
            break;
        }
}

}  // namespace detail

using namespace detail;
using io::decodeScalar;
using io::PlyElement;
using io::PlyHeader;
using io::readPlyHeader;
using io::scalarBytes;

namespace {

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

// Skips `e` in a binary body, walking lists; throws when the body ends early.
size_t skipBinary(const MappedFile& f, size_t off, const PlyElement& e, bool be) {
    const size_t fs = e.fixedBytes();
    if (fs > 0) {
        if (e.count > (f.size() - off) / fs)
            throw Error(f.name(), "PLY element '" + e.name + "' runs past the end of the file");
        return off + fs * e.count;
    }
    for (uint64_t i = 0; i < e.count; ++i) {
        for (const auto& p : e.props) {
            if (!p.isList) {
                off += size_t(scalarBytes(p.type));
                if (off > f.size()) throw Error(f.name(), "PLY body truncated in element '" + e.name + "'");
                continue;
            }
            const size_t cs = size_t(scalarBytes(p.countType));
            if (off + cs > f.size()) throw Error(f.name(), "PLY body truncated in element '" + e.name + "'");
            const double c = decodeScalar(f.data() + off, p.countType, be);
            off += cs;
            if (!(c >= 0) || c * scalarBytes(p.type) > double(f.size() - off))
                throw Error(f.name(), "PLY list in element '" + e.name + "' runs past the end of the file");
            off += size_t(c) * size_t(scalarBytes(p.type));
        }
    }
    return off;
}

}  // namespace

std::optional<PointFileInfo> probePly(const std::string& file) {
    MappedFile f(file);
    const PlyHeader h = readPlyHeader(f);
    const PlyElement* v = h.find("vertex");
    const PlyElement* faces = h.find("face");
    if (!v || (faces && faces->count > 0)) return std::nullopt;
    PointFileInfo info;
    info.format = h.formatName();
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
    const PlyHeader h = readPlyHeader(f);
    const PlyElement* v = h.find("vertex");
    if (!v) throw Error(file, "PLY file has no vertex element");
    if (v->count == 0) throw Error(file, "empty point cloud (0 vertices)");
    const bool be = h.bigEndian();
    // Property slots per attribute.
    struct Slot {
        Attr attr;
        ScalarType type;
        size_t offset;
    };
    std::vector<Slot> slots, scalarSlots;  // scalarSlots: attr holds the scalar's index
    PointSink sink;
    bool has[int(Attr::Count)] = {};
    size_t off = 0;
    for (const auto& p : v->props) {
        if (p.isList) {
            if (!h.ascii()) throw Error(file, "list properties in the vertex element are not supported");
        } else {
            const Attr a = attrOf(p.name);
            if (a != Attr::None && !has[int(a)]) {
                slots.push_back({a, p.type, off});
                has[int(a)] = true;
            } else if (a == Attr::None && scalarAttribute(p.name)) {
                scalarSlots.push_back({Attr(sink.scalars.size()), p.type, off});
                sink.scalars.push_back({p.name, {}});
            }
            off += size_t(scalarBytes(p.type));
        }
    }
    if (!has[int(Attr::X)] || !has[int(Attr::Y)] || !has[int(Attr::Z)])
        throw Error(file, "PLY vertices lack x, y or z");
    PointCloud cloud;
    cloud.format = h.formatName();
    for (const auto& p : v->props) cloud.properties.push_back(p.name);
    const bool hasN = has[int(Attr::NX)] && has[int(Attr::NY)] && has[int(Attr::NZ)];
    const bool hasC = has[int(Attr::R)] && has[int(Attr::G)] && has[int(Attr::B)];
    const size_t n = size_t(v->count);

    if (h.ascii()) {
        // Each value takes at least two bytes ("0 "): a cheap bound before allocating.
        const size_t remaining = f.size() - h.headerBytes;
        if (v->count > remaining / std::max<size_t>(2 * v->props.size(), 2))
            throw Error(file,
                        "PLY header declares " + std::to_string(v->count) + " vertices but the file is too small");
        Tokens tk{f.data() + h.headerBytes, f.data() + f.size()};
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
            size_t s = 0, named = 0;
            for (const auto& p : v->props) {
                if (p.isList) continue;
                const double x = vals[s++];
                const Attr a = attrOf(p.name);
                storeAttr(sink, i, a, x, p.type, hasN, hasC);
                if (a == Attr::None && scalarAttribute(p.name)) sink.scalars[named++].values[i] = float(x);
            }
        }
    } else {
        size_t pos = h.headerBytes;
        for (const auto& e : h.elements) {
            if (&e == v) break;
            pos = skipBinary(f, pos, e, be);
        }
        const size_t stride = v->fixedBytes();
        if (stride == 0) throw Error(file, "PLY vertex element has no fixed-size layout");
        if (v->count > (f.size() - pos) / stride)
            throw Error(file, "PLY header declares " + std::to_string(v->count) + " vertices (" +
                                  std::to_string(v->count * stride) + " bytes) but only " +
                                  std::to_string(f.size() - pos) +
                                  " bytes follow the header (truncated or lying header)");
        sink.reserve(file, n, hasN, hasC, has[int(Attr::Radius)], has[int(Attr::Intensity)]);
        const char* base = f.data() + pos;
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
                        x = decodeScalar(rec + s.offset, s.type, be);
                    }
                    storeAttr(sink, i, s.attr, x, s.type, hasN, hasC);
                }
                for (const Slot& s : scalarSlots)
                    sink.scalars[size_t(s.attr)].values[i] = float(decodeScalar(rec + s.offset, s.type, be));
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

}  // namespace rtfact::points
