// PCD (PCL's point cloud format): header and body are read by us. PCL's own PCDReader was
// used for the body until fuzz_pcd found inputs that passed our strict header checks and
// still crashed inside it (a use-after-free, a 12 GB allocation by a garbage length); the
// strict header rules below remain, so a file we accept is one PCL can read too.

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "core/util/error.h"
#include "core/util/memory_budget.h"
#include "points/point_cloud_io.h"
#include "points/point_cloud_io_detail.h"

namespace rtfact::points {
using namespace detail;

namespace {

struct PcdHeader {
    std::vector<std::string> fields;
    std::vector<int> sizes, counts;
    std::vector<char> types;
    uint64_t width = 0, height = 1, points = 0;
    bool havePoints = false;
    std::string data;
    double viewpoint[7] = {0, 0, 0, 1, 0, 0, 0};
    size_t bodyOffset = 0;
};

// A decimal integer of at most 6 digits, or -1.
int smallInt(const std::string& t) {
    if (t.empty() || t.size() > 6 || t.find_first_not_of("0123456789") != std::string::npos) return -1;
    return std::stoi(t);
}

PcdHeader parsePcdHeader(const MappedFile& f) {
    const std::string& file = f.name();
    PcdHeader h;
    size_t pos = 0;
    bool haveData = false;
    while (pos < f.size() && !haveData) {
        size_t eol = pos;
        while (eol < f.size() && f.data()[eol] != '\n') ++eol;
        if (eol - pos > 65536) throw Error(file, "PCD header line too long (not a PCD file?)");
        std::string line(f.data() + pos, eol - pos);
        pos = std::min(eol + 1, f.size());
        if (line.empty()) continue;
        if (line.back() == '\r') line.pop_back();
        // PCL ends its header at a line of blanks (e.g. "\r") and then reads the body with
        // no fields: it crashed on such a file found by fuzz_pcd. Such lines are errors.
        if (line.find_first_not_of(" \t\r\v\f") == std::string::npos)
            throw Error(file, "blank line inside the PCD header");
        if (line[0] == '#') continue;
        std::istringstream ls(line);
        std::string kw;
        ls >> kw;
        auto readCount = [&](uint64_t& v) {
            std::string t;
            ls >> t;
            if (t.empty() || t[0] == '-' || t.find_first_not_of("0123456789") != std::string::npos || t.size() > 15)
                throw Error(file, "bad PCD " + kw + " value '" + t + "'");
            v = std::stoull(t);
        };
        // PCL's own header parser misbehaves on odd tokens (fuzz_pcd found a crash and a
        // use-after-free inside it): every token must look like what PCL writes.
        if (kw == "VERSION") {
            std::string v;
            ls >> v;
            if (v.empty() || v.size() > 8 || v.find_first_not_of("0123456789.") != std::string::npos)
                throw Error(file, "bad PCD VERSION");
            continue;
        }
        if (kw == "FIELDS" || kw == "COLUMNS") {
            for (std::string s; ls >> s;) {
                const bool ident =
                    s.size() <= 64 && std::all_of(s.begin(), s.end(), [](char c) {
                        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
                    });
                if (!ident) throw Error(file, "bad PCD field name '" + s.substr(0, 32) + "'");
                h.fields.push_back(s);
            }
        } else if (kw == "SIZE") {
            for (std::string t; ls >> t;) {
                const int s = smallInt(t);
                if (s != 1 && s != 2 && s != 4 && s != 8) throw Error(file, "bad PCD SIZE '" + t.substr(0, 32) + "'");
                h.sizes.push_back(s);
            }
        } else if (kw == "TYPE") {
            std::string s;
            while (ls >> s) {
                if (s != "F" && s != "I" && s != "U") throw Error(file, "bad PCD TYPE '" + s + "'");
                h.types.push_back(s[0]);
            }
        } else if (kw == "COUNT") {
            // Every token must be a small integer: a stream read that overflows would just
            // stop here, and PCL would then allocate by its own reading of the number.
            for (std::string t; ls >> t;) {
                const int s = smallInt(t);
                if (s < 1 || s > 4096) throw Error(file, "bad PCD COUNT '" + t.substr(0, 32) + "'");
                h.counts.push_back(s);
            }
        } else if (kw == "WIDTH")
            readCount(h.width);
        else if (kw == "HEIGHT")
            readCount(h.height);
        else if (kw == "POINTS") {
            readCount(h.points);
            h.havePoints = true;
        } else if (kw == "VIEWPOINT") {
            for (double& v : h.viewpoint) {
                std::string t;
                ls >> t;
                char* end = nullptr;
                v = std::strtod(t.c_str(), &end);
                if (t.empty() || *end != '\0' || !std::isfinite(v))
                    throw Error(file, "bad PCD VIEWPOINT (seven numbers expected)");
            }
        } else if (kw == "DATA") {
            ls >> h.data;
            haveData = true;
        } else {
            throw Error(file, "unexpected PCD header line '" + line.substr(0, 64) + "'");
        }
    }
    if (!haveData) throw Error(file, "PCD header has no DATA line (truncated or not a PCD file)");
    h.bodyOffset = pos;
    if (h.fields.empty()) throw Error(file, "PCD header has no FIELDS");
    if (h.counts.empty()) h.counts.assign(h.fields.size(), 1);
    if (h.sizes.size() != h.fields.size() || h.types.size() != h.fields.size() || h.counts.size() != h.fields.size())
        throw Error(file, "PCD header: FIELDS, SIZE, TYPE and COUNT have different lengths");
    for (size_t k = 0; k < h.fields.size(); ++k)
        if (h.types[k] == 'F' && h.sizes[k] != 4 && h.sizes[k] != 8)
            throw Error(file, "PCD field '" + h.fields[k] + "' is a float of " + std::to_string(h.sizes[k]) +
                                  " bytes (4 or 8 expected)");
    if (!h.havePoints) h.points = h.width * h.height;
    if (h.width > (uint64_t(1) << 40) || h.height > (uint64_t(1) << 40) || h.width * h.height != h.points)
        throw Error(file, "PCD header: WIDTH x HEIGHT (" + std::to_string(h.width) + " x " + std::to_string(h.height) +
                              ") differs from POINTS " + std::to_string(h.points));
    if (h.data != "ascii" && h.data != "binary" && h.data != "binary_compressed")
        throw Error(file, "unknown PCD DATA '" + h.data + "'");
    return h;
}

size_t rowSize(const PcdHeader& h) {
    size_t s = 0;
    for (size_t i = 0; i < h.fields.size(); ++i) s += size_t(h.sizes[i]) * size_t(h.counts[i]);
    return s;
}

// The size checks PCL does not do.
void validateBody(const MappedFile& f, const PcdHeader& h) {
    const std::string& file = f.name();
    if (h.points == 0) throw Error(file, "empty point cloud (POINTS 0)");
    const size_t remaining = f.size() - h.bodyOffset;
    const size_t row = rowSize(h);
    if (h.data == "ascii") {
        size_t values = 0;
        for (int c : h.counts) values += size_t(c);
        if (h.points > remaining / (2 * values))
            throw Error(file, "PCD header declares " + std::to_string(h.points) + " points but the file is too small");
        // Every point is one line of exactly `values` tokens (PCL only warns and skips).
        const char* p = f.data() + h.bodyOffset;
        const char* end = f.data() + f.size();
        for (uint64_t i = 0; i < h.points; ++i) {
            while (p < end && (*p == '\n' || *p == '\r')) ++p;  // PCL skips empty lines
            if (p == end)
                throw Error(file,
                            "PCD body ends after " + std::to_string(i) + " of " + std::to_string(h.points) + " points");
            size_t tokens = 0;
            bool inToken = false;
            for (; p < end && *p != '\n'; ++p) {
                const bool blank = *p == ' ' || *p == '\t' || *p == '\r';
                tokens += !blank && !inToken;
                inToken = !blank;
            }
            if (tokens != values)
                throw Error(file, "PCD point " + std::to_string(i + 1) + " has " + std::to_string(tokens) +
                                      " values, expected " + std::to_string(values));
        }
    } else if (h.data == "binary") {
        if (h.points > remaining / row)
            throw Error(file, "PCD header declares " + std::to_string(h.points) + " points (" +
                                  std::to_string(h.points * row) + " bytes) but only " + std::to_string(remaining) +
                                  " bytes follow the header");
    } else {
        if (remaining < 8) throw Error(file, "PCD compressed body truncated (no size words)");
        uint32_t csize, usize;
        std::memcpy(&csize, f.data() + h.bodyOffset, 4);
        std::memcpy(&usize, f.data() + h.bodyOffset + 4, 4);
        if (csize > remaining - 8)
            throw Error(file,
                        "PCD compressed block of " + std::to_string(csize) + " bytes runs past the end of the file");
        if (uint64_t(usize) != h.points * row)
            throw Error(file, "PCD uncompressed size " + std::to_string(usize) + " differs from POINTS x row size " +
                                  std::to_string(h.points * row));
        // LZF expands at most 8x + a little; anything more is a lying header.
        if (uint64_t(usize) > uint64_t(csize) * 9 + 64)
            throw Error(file, "PCD uncompressed size is implausible for the compressed block");
    }
}

// Stores an ASCII value with the field's declared type (PCL writes packed rgb as a float
// whose bits are the colour, or as an unsigned integer).
void writeScalar(char* dst, char type, int size, double v) {
    if (type == 'F') {
        if (size == 8)
            std::memcpy(dst, &v, 8);
        else {
            const float f = float(v);
            std::memcpy(dst, &f, 4);
        }
        return;
    }
    // 9.2e18 keeps 8-byte values inside int64_t.
    const double lo = type == 'U' ? 0.0 : std::max(-9.2e18, -std::ldexp(1.0, 8 * size - 1));
    const double hi = std::min(9.2e18, type == 'U' ? std::ldexp(1.0, 8 * size) - 1 : std::ldexp(1.0, 8 * size - 1) - 1);
    const double c = std::isfinite(v) ? std::clamp(std::round(v), lo, hi) : 0.0;
    const int64_t x = int64_t(c);
    std::memcpy(dst, &x, size_t(size));  // little-endian: the low bytes
}

ScalarType scalarTypeOf(char type, int size) {
    if (type == 'F') return size == 8 ? ScalarType::F64 : ScalarType::F32;  // SIZE checked: 4 or 8
    const bool u = type == 'U';
    switch (size) {
        case 1:
            return u ? ScalarType::U8 : ScalarType::I8;
        case 2:
            return u ? ScalarType::U16 : ScalarType::I16;
        default:
            return u ? ScalarType::U32 : ScalarType::I32;  // 8-byte integers: their low 4 bytes
    }
}

// LZF as PCL writes it: a control byte c < 32 starts a run of c + 1 literal bytes; otherwise
// a back reference of (c >> 5) + 2 bytes (7 -> one more length byte) at distance
// ((c & 31) << 8) + next byte + 1. Every read and write is bounds-checked.
void lzfDecompress(const std::string& file, const unsigned char* in, size_t inSize, char* out, size_t outSize) {
    size_t ip = 0, op = 0;
    auto bad = [&] { throw Error(file, "corrupt PCD compressed block"); };
    while (ip < inSize) {
        const unsigned c = in[ip++];
        if (c < 32) {
            const size_t len = c + 1;
            if (ip + len > inSize || op + len > outSize) bad();
            std::memcpy(out + op, in + ip, len);
            ip += len, op += len;
        } else {
            size_t len = c >> 5;
            if (ip >= inSize) bad();
            if (len == 7) {
                len += in[ip++];
                if (ip >= inSize) bad();
            }
            const size_t dist = ((size_t(c) & 31) << 8) + in[ip++] + 1;
            len += 2;
            if (dist > op || op + len > outSize) bad();
            for (size_t k = 0; k < len; ++k, ++op) out[op] = out[op - dist];  // may overlap
        }
    }
    if (op != outSize)
        throw Error(file, "PCD compressed block decodes to " + std::to_string(op) + " bytes, expected " +
                              std::to_string(outSize));
}

// The body as n records of rowSize(h) bytes, whatever its encoding (checked by validateBody).
std::vector<char> decodeRows(const std::string& file, const PcdHeader& h) {
    MappedFile f(file);
    const size_t n = size_t(h.points), row = rowSize(h);
    std::vector<char> rows(n * row);
    const char* body = f.data() + h.bodyOffset;
    if (h.data == "binary") {
        std::memcpy(rows.data(), body, n * row);
    } else if (h.data == "binary_compressed") {
        uint32_t csize, usize;
        std::memcpy(&csize, body, 4);
        std::memcpy(&usize, body + 4, 4);
        std::vector<char> soa(usize);
        lzfDecompress(file, reinterpret_cast<const unsigned char*>(body + 8), csize, soa.data(), soa.size());
        // Field-major (all x, then all y, ...) to records.
        size_t src = 0, offset = 0;
        for (size_t k = 0; k < h.fields.size(); ++k) {
            const size_t w = size_t(h.sizes[k]) * size_t(h.counts[k]);
            for (size_t i = 0; i < n; ++i, src += w) std::memcpy(rows.data() + i * row + offset, soa.data() + src, w);
            offset += w;
        }
    } else {
        // ASCII: one line per point, tokens in field order (validateBody counted them).
        const char* p = body;
        const char* end = f.data() + f.size();
        std::string tok;
        for (size_t i = 0; i < n; ++i) {
            while (p < end && (*p == '\n' || *p == '\r')) ++p;
            char* rec = rows.data() + i * row;
            for (size_t k = 0; k < h.fields.size(); ++k) {
                for (int c = 0; c < h.counts[k]; ++c, rec += h.sizes[k]) {
                    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
                    const char* t0 = p;
                    while (p < end && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n') ++p;
                    tok.assign(t0, p);
                    char* e = nullptr;
                    const double v = std::strtod(tok.c_str(), &e);
                    if (tok.empty() || *e != '\0')
                        throw Error(file, "bad number '" + tok.substr(0, 32) + "' for point " + std::to_string(i + 1));
                    writeScalar(rec, h.types[k], h.sizes[k], v);
                }
            }
            while (p < end && *p != '\n') ++p;
        }
    }
    return rows;
}
}  // namespace

std::optional<PointFileInfo> probePcd(const std::string& file) {
    MappedFile f(file);
    const PcdHeader h = parsePcdHeader(f);
    PointFileInfo info;
    info.format = "pcd " + h.data;
    info.points = h.points;
    info.properties = h.fields;
    return info;
}

PointCloud loadPcd(const std::string& file) {
    PcdHeader h;
    {
        MappedFile f(file);
        h = parsePcdHeader(f);
        validateBody(f, h);
    }
    const size_t n = size_t(h.points);
    const size_t row = rowSize(h);
    checkMemory(file, uint64_t(n) * row, "the decoded body of " + std::to_string(n) + " points",
                "subsample the cloud, e.g. with pcl_voxel_grid");
    const std::vector<char> rows = decodeRows(file, h);
    struct Slot {
        Attr attr;
        ScalarType type;
        size_t offset;
    };
    std::vector<Slot> slots, scalarSlots;  // scalarSlots: attr holds the scalar's index
    PointSink sink;
    int rgbOffset = -1;
    bool has[int(Attr::Count)] = {};
    PointCloud cloud;
    cloud.format = "pcd " + h.data;
    size_t offset = 0;
    for (size_t k = 0; k < h.fields.size(); offset += size_t(h.sizes[k]) * size_t(h.counts[k]), ++k) {
        const std::string& name = h.fields[k];
        cloud.properties.push_back(name);
        const ScalarType t = scalarTypeOf(h.types[k], h.sizes[k]);
        if ((name == "rgb" || name == "rgba") && h.sizes[k] == 4) {
            rgbOffset = int(offset);
            continue;
        }
        const Attr a = attrOf(name);
        if (a == Attr::None && scalarAttribute(name)) {
            scalarSlots.push_back({Attr(sink.scalars.size()), t, offset});
            sink.scalars.push_back({name, {}});
        }
        if (a == Attr::None || a == Attr::R || a == Attr::G || a == Attr::B || has[int(a)]) continue;
        has[int(a)] = true;
        slots.push_back({a, t, offset});
    }
    if (!has[int(Attr::X)] || !has[int(Attr::Y)] || !has[int(Attr::Z)]) throw Error(file, "PCD points lack x, y or z");
    const bool hasN = has[int(Attr::NX)] && has[int(Attr::NY)] && has[int(Attr::NZ)];
    sink.reserve(file, n, hasN, rgbOffset >= 0, has[int(Attr::Radius)], has[int(Attr::Intensity)]);
    for (size_t i = 0; i < n; ++i) {
        const char* rec = rows.data() + i * row;
        // Separate R/G/B fields are skipped above: colour comes from the packed rgb only.
        for (const Slot& s : slots)
            storeAttr(sink, i, s.attr, io::decodeScalar(rec + s.offset, s.type, false), s.type, hasN, false);
        for (const Slot& s : scalarSlots)
            sink.scalars[size_t(s.attr)].values[i] = float(io::decodeScalar(rec + s.offset, s.type, false));
        if (rgbOffset >= 0) {
            uint32_t packed;  // 0x00RRGGBB whatever the declared type (F or U)
            std::memcpy(&packed, rec + rgbOffset, 4);
            sink.col[i] = {uint8_t(packed >> 16), uint8_t(packed >> 8), uint8_t(packed)};
        }
    }
    sink.finish(file, cloud);
    const double vp[3] = {h.viewpoint[0], h.viewpoint[1], h.viewpoint[2]};
    cloud.viewpoint =
        Vec3f(float(vp[0] - cloud.origin[0]), float(vp[1] - cloud.origin[1]), float(vp[2] - cloud.origin[2]));
    cloud.hasViewpoint = true;
    return cloud;
}

}  // namespace rtfact::points
