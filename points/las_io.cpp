// LAS/LAZ point records into a PointCloud. The file is mapped; the header (checked against
// the file before anything is allocated) gives the layout; blocks of records decode in
// parallel straight into the cloud's arrays. LAZ data is first decompressed into plain
// records by the LAZ decoder, then decoded the same way.
#include "points/las_io.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>

#include "core/io/mapped_file.h"
#include "core/io/scalar_type.h"
#include "core/util/error.h"
#include "core/util/huge_pages.h"
#include "core/util/memory_budget.h"
#include "points/laz_decoder.h"
#include "points/point_cloud_io.h"
#include "points/point_cloud_io_detail.h"

namespace rtfact::points {

namespace las {

namespace {

template <typename T>
T le(const uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof v);  // LAS is little-endian; so are the machines we build for
    return v;
}

std::span<const uint8_t> bytesOf(const io::MappedFile& m) {
    return {reinterpret_cast<const uint8_t*>(m.data()), m.size()};
}

// Where the optional fields of each format sit in its record (-1: absent).
struct Layout {
    bool legacy = true;  // formats 0-5: 20-byte core; 6-10: 30-byte core
    int gps = -1, rgb = -1, nir = -1;
};

Layout layoutOf(int f) {
    Layout l;
    l.legacy = f <= 5;
    if (f == 1 || f == 3 || f == 4 || f == 5) l.gps = 20;
    if (f >= 6) l.gps = 22;
    if (f == 2) l.rgb = 20;
    if (f == 3 || f == 5) l.rgb = 28;
    if (f == 7 || f == 8 || f == 10) l.rgb = 30;
    if (f == 8 || f == 10) l.nir = 36;
    return l;
}

double extraValue(const uint8_t* p, int type) {
    switch (type) {
        case 1:
            return p[0];
        case 2:
            return int8_t(p[0]);
        case 3:
            return le<uint16_t>(p);
        case 4:
            return le<int16_t>(p);
        case 5:
            return le<uint32_t>(p);
        case 6:
            return le<int32_t>(p);
        case 7:
            return double(le<uint64_t>(p));
        case 8:
            return double(le<int64_t>(p));
        case 9:
            return le<float>(p);
        default:
            return le<double>(p);
    }
}

// The point records of a file: in the mapping (LAS) or decompressed (LAZ).
struct Records {
    io::MappedFile map;
    Header header;
    std::vector<uint8_t> decompressed;
    const uint8_t* data = nullptr;

    Records(const std::string& file, int threads) : map(file) {
        const std::span<const uint8_t> f = bytesOf(map);
        header = readHeader(f, file);
        const Header& h = header;
        if (h.pointCount == 0) throw Error(file, "LAS file holds no points");
        if (!h.compressed) {
            data = f.data() + h.pointDataOffset;
            return;
        }
        const Vlr* v = findVlr(h, "laszip encoded", 22204);
        if (!v) throw Error(file, "LAZ file (compressed point format) without its 'laszip encoded' VLR");
        const laz::LazInfo info = laz::parseLazVlr(payload(f, *v), file);
        if (info.recordLength() != h.recordLength)
            throw Error(file, "LAZ items decode to " + std::to_string(info.recordLength()) +
                                  "-byte records but the header says " + std::to_string(h.recordLength));
        const uint64_t bytes = h.pointCount * h.recordLength;
        checkMemory(file, bytes, "the decompressed records of " + std::to_string(h.pointCount) + " points");
        decompressed.resize(bytes);
        laz::decompress(info, f, h.pointDataOffset, h.pointCount, decompressed, threads, file);
        data = decompressed.data();
    }
    const uint8_t* record(uint64_t i) const { return data + i * header.recordLength; }
};

// Runs f on up to `threads` threads (0: all cores).
template <class F>
void withThreads(int threads, F&& f) {
    if (threads > 0) {
        tbb::task_arena arena(threads);
        arena.execute(f);
    } else {
        f();
    }
}

}  // namespace

int extraTypeSize(int type) {
    static constexpr int sizes[] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    return type >= 1 && type <= 10 ? sizes[type] : 0;
}

std::vector<ExtraField> parseExtraBytes(const Header& h, std::span<const uint8_t> file, const std::string& source) {
    std::vector<ExtraField> out;
    const uint32_t base = minimumRecordLength(h.pointFormat);
    const uint32_t room = h.recordLength - base;
    uint32_t used = 0;
    for (const Vlr& v : h.vlrs) {
        if (v.userId != "LASF_Spec" || v.recordId != 4) continue;
        if (v.size % 192 != 0)
            throw Error(source, "Extra Bytes VLR of " + std::to_string(v.size) +
                                    " bytes is not a whole number of 192-byte descriptors");
        const std::span<const uint8_t> p = payload(file, v);
        for (size_t d = 0; d < v.size / 192; ++d) {
            const uint8_t* e = p.data() + 192 * d;
            const int type = e[2], options = e[3];
            std::string name(reinterpret_cast<const char*>(e + 4), 32);
            name.resize(std::strlen(name.c_str()));
            int count = 1, base_type = type;
            uint32_t bytes = 0;
            if (type == 0) {
                bytes = uint32_t(options);  // undocumented: options holds the byte count
            } else if (type <= 30) {
                count = (type - 1) / 10 + 1;
                base_type = (type - 1) % 10 + 1;
                bytes = uint32_t(count * extraTypeSize(base_type));
            } else {
                throw Error(source, "extra bytes '" + name + "' have unknown data type " + std::to_string(type));
            }
            if (used + bytes > room)
                throw Error(source, "Extra Bytes VLRs describe more than the " + std::to_string(room) +
                                        " extra bytes of each " + std::to_string(h.recordLength) + "-byte record");
            for (int k = 0; type != 0 && k < count; ++k) {
                ExtraField f;
                f.name = count == 1 ? name : name + "[" + std::to_string(k) + "]";
                f.type = uint8_t(base_type);
                f.offset = base + used + uint32_t(k * extraTypeSize(base_type));
                const double scale = le<double>(e + 112 + 8 * k), add = le<double>(e + 136 + 8 * k);
                if ((options & 8) && std::isfinite(scale) && scale != 0) f.scale = scale;
                if ((options & 16) && std::isfinite(add)) f.add = add;
                out.push_back(std::move(f));
            }
            used += bytes;
        }
    }
    return out;
}

std::string crsText(const Header& h, std::span<const uint8_t> file) {
    for (const Vlr& v : h.vlrs)
        if (v.userId == "LASF_Projection" && v.recordId == 2112) {
            const std::span<const uint8_t> p = payload(file, v);
            std::string s(reinterpret_cast<const char*>(p.data()), p.size());
            s.resize(std::strlen(s.c_str()));
            if (!s.empty()) return s;
        }
    const Vlr* g = findVlr(h, "LASF_Projection", 34735);
    if (!g || g->size < 8) return {};
    // GeoKeyDirectory: 4 header words (the last the key count), then 4 words per key;
    // the keys naming the model and EPSG codes are stored inline (location 0).
    const std::span<const uint8_t> p = payload(file, *g);
    const size_t keys = std::min<size_t>(le<uint16_t>(p.data() + 6), (p.size() - 8) / 8);
    std::string model, codes;
    for (size_t k = 0; k < keys; ++k) {
        const uint8_t* e = p.data() + 8 + 8 * k;
        const uint16_t id = le<uint16_t>(e), loc = le<uint16_t>(e + 2), value = le<uint16_t>(e + 6);
        if (loc != 0) continue;
        if (id == 1024) model = value == 1 ? "projected" : value == 2 ? "geographic" : value == 3 ? "geocentric" : "";
        const char* what = id == 2048 ? "geographic" : id == 3072 ? "projected" : id == 4096 ? "vertical" : nullptr;
        if (what && value != 32767)
            codes += std::string(codes.empty() ? "" : ", ") + what + " EPSG:" + std::to_string(value);
    }
    if (model.empty() && codes.empty()) return "GeoTIFF keys";
    return "GeoTIFF keys: " + (model.empty() ? "" : model + " model") + (model.empty() || codes.empty() ? "" : ", ") +
           codes;
}

Summary summarize(const std::string& file) {
    Records r(file, 0);
    Summary s;
    s.header = r.header;
    const std::span<const uint8_t> f = bytesOf(r.map);
    s.crs = crsText(r.header, f);
    s.extra = parseExtraBytes(r.header, f, file);
    const bool legacy = r.header.pointFormat <= 5;
    for (uint64_t i = 0; i < r.header.pointCount; ++i) {
        const uint8_t* p = r.record(i);
        ++s.byClass[legacy ? p[15] & 31 : p[16]];
        ++s.byReturn[legacy ? p[14] & 7 : p[14] & 15];
    }
    return s;
}

}  // namespace las

using namespace las;

namespace {
// The attribute names a file of this layout holds (x y z ..., then its extra bytes).
std::vector<std::string> propertiesOf(const Header& h, const std::vector<ExtraField>& extra) {
    const Layout l = layoutOf(h.pointFormat);
    std::vector<std::string> p = {"x",
                                  "y",
                                  "z",
                                  "intensity",
                                  "return_number",
                                  "number_of_returns",
                                  "classification",
                                  "scan_angle",
                                  "user_data",
                                  "point_source_id"};
    if (l.gps >= 0) p.push_back("gps_time");
    if (l.rgb >= 0) p.insert(p.end(), {"red", "green", "blue"});
    if (l.nir >= 0) p.push_back("nir");
    for (const ExtraField& e : extra) p.push_back(e.name);
    return p;
}

std::string formatName(const Header& h) {
    return std::string(h.compressed ? "laz " : "las ") + std::to_string(h.versionMajor) + "." +
           std::to_string(h.versionMinor) + " format " + std::to_string(h.pointFormat);
}
}  // namespace

std::optional<PointFileInfo> probeLas(const std::string& file) {
    io::MappedFile m(file);
    const Header h = readHeader(bytesOf(m), file);
    PointFileInfo info;
    info.format = formatName(h);
    info.points = h.pointCount;
    info.properties = propertiesOf(h, parseExtraBytes(h, bytesOf(m), file));
    return info;
}

PointCloud loadLas(const std::string& file, const LoadFilter& filter, int threads) {
    const Records r(file, threads);
    const Header& h = r.header;
    const std::span<const uint8_t> f = bytesOf(r.map);
    const std::vector<ExtraField> extra = parseExtraBytes(h, f, file);
    for (int a = 0; a < 3; ++a)
        if (std::fabs(h.scale[a]) * 2147483648.0 + std::fabs(h.offset[a]) > 1e18)
            throw Error(file, "scale and offset of axis " + std::to_string(a) + " give coordinates beyond 1e18");
    const Layout l = layoutOf(h.pointFormat);
    const size_t n = size_t(h.pointCount);

    // The scalars: GPS time, scan angle, user data, point source id, NIR, extra bytes.
    struct Scalar {
        std::string name;
        int type;  // extra-bytes data type of the stored value
        uint32_t offset;
        double scale = 1, add = 0;
    };
    std::vector<Scalar> scalars;
    if (l.gps >= 0) scalars.push_back({"gps_time", 10, uint32_t(l.gps)});
    if (l.legacy)
        scalars.push_back({"scan_angle", 2, 16});
    else
        scalars.push_back({"scan_angle", 4, 18, 0.006});
    scalars.push_back({"user_data", 1, 17});
    scalars.push_back({"point_source_id", 3, uint32_t(l.legacy ? 18 : 20)});
    if (l.nir >= 0) scalars.push_back({"nir", 3, uint32_t(l.nir)});
    for (const ExtraField& e : extra) scalars.push_back({e.name, e.type, e.offset, e.scale, e.add});

    const uint64_t perPoint = 12 + 4 + 3 + (l.rgb >= 0 ? 3 : 0) + 4 * scalars.size();
    checkMemory(file, n * perPoint, "the attributes of " + std::to_string(n) + " points",
                "crop the tile first, e.g. with pdal or lastools");

    PointCloud c;
    c.format = formatName(h);
    c.crs = crsText(h, f);
    auto coord = [&](const uint8_t* p, int a) { return double(le<int32_t>(p + 4 * a)) * h.scale[a] + h.offset[a]; };
    // (the decode below computes the same expression: x * scale + offset - origin)
    // The origin shift of the other loaders: the first point, rounded, when far from 0.
    const double p0[3] = {coord(r.record(0), 0), coord(r.record(0), 1), coord(r.record(0), 2)};
    if (std::max({std::fabs(p0[0]), std::fabs(p0[1]), std::fabs(p0[2])}) > 1e4)
        c.origin = {std::round(p0[0]), std::round(p0[1]), std::round(p0[2])};
    c.properties = propertiesOf(h, extra);

    c.scalars.resize(scalars.size());
    for (size_t k = 0; k < scalars.size(); ++k) {
        c.scalars[k].name = scalars[k].name;
        // Large values (GPS seconds) keep their precision relative to the first point's.
        if (scalars[k].name == "gps_time") c.scalars[k].offset = extraValue(r.record(0) + scalars[k].offset, 10);
    }
    std::atomic<uint16_t> maxRgb{0};
    const std::array<double, 3> o = c.origin;
    const uint32_t stride = h.recordLength;
    withThreads(threads, [&] {
        // Fresh memory on huge pages, the arrays first-touched side by side: zeroing new
        // pages costs as much as decoding on a VM.
        tbb::task_group g;
        g.run([&] { resizeFreshHugePages(c.positions, n); });
        g.run([&] { resizeFreshHugePages(c.intensities, n); });
        g.run([&] {
            resizeFreshHugePages(c.classes, n);
            resizeFreshHugePages(c.returnNumbers, n);
            resizeFreshHugePages(c.returnCounts, n);
            if (l.rgb >= 0) resizeFreshHugePages(c.colors, n);
        });
        for (ScalarField& f : c.scalars) g.run([&f, n] { resizeFreshHugePages(f.values, n); });
        g.wait();
        // Blocks that stay in L2 while every field is read out of them; raw pointers, so
        // that the byte stores do not make the compiler reload the arrays' addresses.
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& br) {
            const size_t b = br.begin(), e = br.end();
            const uint8_t* base = r.data;
            Vec3f* pos = c.positions.data();
            float* inten = c.intensities.data();
            uint8_t *cls = c.classes.data(), *rn = c.returnNumbers.data(), *rc = c.returnCounts.data();
            const double s0 = h.scale[0], s1 = h.scale[1], s2 = h.scale[2];
            const double a0 = h.offset[0], a1 = h.offset[1], a2 = h.offset[2];
            for (size_t i = b; i < e; ++i) {
                const uint8_t* p = base + i * stride;
                pos[i] = Vec3f(float(double(le<int32_t>(p)) * s0 + a0 - o[0]),
                               float(double(le<int32_t>(p + 4)) * s1 + a1 - o[1]),
                               float(double(le<int32_t>(p + 8)) * s2 + a2 - o[2]));
                inten[i] = float(le<uint16_t>(p + 12));
                const uint8_t flags = p[14];
                rn[i] = l.legacy ? flags & 7 : flags & 15;
                rc[i] = l.legacy ? (flags >> 3) & 7 : flags >> 4;
                cls[i] = l.legacy ? p[15] & 31 : p[16];
            }
            if (l.rgb >= 0) {
                std::array<uint8_t, 3>* col = c.colors.data();
                uint16_t localMax = 0;
                for (size_t i = b; i < e; ++i) {
                    const uint8_t* p = base + i * stride + l.rgb;
                    const uint16_t rr = le<uint16_t>(p), gg = le<uint16_t>(p + 2), bb = le<uint16_t>(p + 4);
                    localMax = std::max({localMax, rr, gg, bb});
                    col[i] = {uint8_t(rr >> 8), uint8_t(gg >> 8), uint8_t(bb >> 8)};
                }
                uint16_t m = maxRgb.load();
                while (localMax > m && !maxRgb.compare_exchange_weak(m, localMax)) {
                }
            }
            for (size_t k = 0; k < scalars.size(); ++k) {
                const Scalar& sc = scalars[k];
                float* out = c.scalars[k].values.data();
                const double scale = sc.scale, add = sc.add - c.scalars[k].offset;
                const uint8_t* p = base + sc.offset;
                // One loop per stored type: no switch per value.
                auto run = [&]<class T>(T) {
                    for (size_t i = b; i < e; ++i) out[i] = float(double(le<T>(p + i * stride)) * scale + add);
                };
                switch (sc.type) {
                    case 1:
                        run(uint8_t{});
                        break;
                    case 2:
                        run(int8_t{});
                        break;
                    case 3:
                        run(uint16_t{});
                        break;
                    case 4:
                        run(int16_t{});
                        break;
                    case 5:
                        run(uint32_t{});
                        break;
                    case 6:
                        run(int32_t{});
                        break;
                    case 7:
                        run(uint64_t{});
                        break;
                    case 8:
                        run(int64_t{});
                        break;
                    case 9:
                        run(float{});
                        break;
                    default:
                        run(double{});
                        break;
                }
            }
        });
    });
    if (l.rgb >= 0) {
        if (maxRgb.load() == 0) {
            c.colors = {};  // the format has colour fields, the file no colours
        } else if (maxRgb.load() <= 255) {
            // Writers that store 8-bit colours unscaled: the low bytes are the colour.
            tbb::parallel_for(size_t(0), n, [&](size_t i) {
                const uint8_t* p = r.record(i) + l.rgb;
                c.colors[i] = {p[0], p[2], p[4]};
            });
        }
    }
    if (filter.active()) applyLoadFilter(c, filter, file);
    return c;
}

}  // namespace rtfact::points
