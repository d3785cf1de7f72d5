// PLY data reader (ASCII, binary little/big endian). Ours rather than VTK's: vtkPLYReader
// crashes on corrupted face lists (found by flipping bytes of a real file), and every
// count and index here is checked against the bytes actually present.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "core/util/error.h"
#include "surfaces/mesh.h"
#include "surfaces/ply_header.h"

namespace rtfact {

namespace {

// Which element entry is being read, for messages only (built when one is needed).
struct Where {
    const std::string& element;
    uint64_t k;
    std::string str() const { return element + " " + std::to_string(k); }
};

class PlyData {
   public:
    PlyData(const std::string& file, const PlyHeader& h) : file_(file), h_(h) {
        std::ifstream in(file, std::ios::binary);
        in.seekg(std::streamoff(h.headerBytes));
        // The size was checked against the announced elements; the buffer is the file.
        buf_.resize(size_t(h.fileBytes - h.headerBytes));
        in.read(buf_.data(), std::streamsize(buf_.size()));
        if (size_t(in.gcount()) != buf_.size()) throw Error(file, "cannot read PLY data");
    }
    double value(char kind, int bytes) {
        if (h_.format == PlyHeader::Format::Ascii) return asciiValue();
        if (pos_ + size_t(bytes) > buf_.size()) throw Error(file_, "truncated PLY data (premature end of file)");
        unsigned char b[8];
        std::memcpy(b, buf_.data() + pos_, size_t(bytes));
        pos_ += size_t(bytes);
        if (h_.format == PlyHeader::Format::BinaryBE)
            for (int i = 0; i < bytes / 2; ++i) std::swap(b[i], b[bytes - 1 - i]);
        if (kind == 'f') {
            if (bytes == 4) {
                float f;
                std::memcpy(&f, b, 4);
                return f;
            }
            double d;
            std::memcpy(&d, b, 8);
            return d;
        }
        uint64_t u = 0;
        std::memcpy(&u, b, size_t(bytes));  // little endian host
        if (kind == 'u') return double(u);
        const int shift = 64 - 8 * bytes;
        return double(int64_t(u << shift) >> shift);
    }

    // A list's length, checked against the bytes left, so that a corrupt count can drive
    // neither a long loop nor an allocation.
    uint64_t listLength(const PlyProperty& p, const Where& where) {
        const double c = value(p.countKind, p.countBytes);
        if (!(c >= 0) || c != std::floor(c)) throw Error(file_, where.str() + ": bad list length " + number(c));
        // Binary values take their size; ASCII ones a character and a separator (but the last).
        const double fits = ascii() ? double(remaining() + 1) / 2 : double(remaining()) / p.typeBytes;
        if (c > fits)
            throw Error(file_, "truncated or corrupt PLY data: " + where.str() + " lists " + number(c) +
                                   " values but only " + std::to_string(remaining()) + " bytes are left");
        return uint64_t(c);
    }
    void skipList(const PlyProperty& p, uint64_t n) {
        for (uint64_t j = 0; j < n; ++j) value(p.typeKind, p.typeBytes);
    }
    bool ascii() const { return h_.format == PlyHeader::Format::Ascii; }
    const std::string& file() const { return file_; }
    size_t remaining() const { return buf_.size() - pos_; }
    // Short text for any double (a corrupt value may be 1e300).
    static std::string number(double v) {
        char b[32];
        std::snprintf(b, sizeof b, "%.10g", v);
        return b;
    }

   private:
    double asciiValue() {
        while (pos_ < buf_.size() && std::isspace(static_cast<unsigned char>(buf_[pos_]))) ++pos_;
        if (pos_ >= buf_.size()) throw Error(file_, "truncated PLY data (premature end of file)");
        size_t e = pos_;
        while (e < buf_.size() && !std::isspace(static_cast<unsigned char>(buf_[e]))) ++e;
        const std::string tok(buf_.data() + pos_, e - pos_);
        pos_ = e;
        char* end = nullptr;
        const double v = std::strtod(tok.c_str(), &end);
        if (end != tok.c_str() + tok.size()) throw Error(file_, "bad number '" + tok.substr(0, 32) + "' in PLY data");
        return v;
    }
    std::string file_;
    const PlyHeader& h_;
    std::vector<char> buf_;
    size_t pos_ = 0;
};

// One vertex index of a face or strip: an integer below the vertex count.
uint32_t vertexIndex(const std::string& file, double x, uint64_t nv, const Where& where) {
    if (!(x >= 0 && x < double(nv)) || x != std::floor(x))
        throw Error(file, where.str() + " refers to vertex " + PlyData::number(x) + " of " + std::to_string(nv));
    return uint32_t(x);
}

// A polygon of n vertices, fanned from its first; degenerate triangles are dropped.
void readPolygon(PlyData& data, const PlyProperty& p, uint64_t n, uint64_t nv, const Where& where,
                 std::vector<uint32_t>& out) {
    uint32_t first = 0, prev = 0;
    for (uint64_t j = 0; j < n; ++j) {
        const uint32_t id = vertexIndex(data.file(), data.value(p.typeKind, p.typeBytes), nv, where);
        if (j == 0)
            first = id;
        else if (j >= 2 && first != prev && prev != id && first != id)
            out.insert(out.end(), {first, prev, id});
        prev = id;
    }
}

// Triangle strips: -1 (or, binary unsigned, the all-ones value: primitive restart) ends
// a strip. Every second triangle of a strip is reversed (b, a, c) so all keep the
// orientation of the first; degenerate ones (used to stitch strips) are dropped but still
// count for the alternation.
void readStrip(PlyData& data, const PlyProperty& p, uint64_t n, uint64_t nv, const Where& where,
               std::vector<uint32_t>& out) {
    const double restartU = p.typeKind == 'u' && !data.ascii() ? std::ldexp(1.0, 8 * p.typeBytes) - 1 : -1;
    uint64_t run = 0;  // indices in the current strip
    uint32_t a = 0, b = 0;
    for (uint64_t j = 0; j < n; ++j) {
        const double x = data.value(p.typeKind, p.typeBytes);
        if (x == -1 || x == restartU) {
            run = 0;
            continue;
        }
        if (!(x >= 0 && x < double(nv)) || x != std::floor(x))
            throw Error(data.file(), where.str() + " entry " + std::to_string(j) + " refers to vertex " +
                                         PlyData::number(x) + " of " + std::to_string(nv) + " (only -1 ends a strip)");
        const uint32_t c = uint32_t(x);
        if (run >= 2 && a != b && b != c && a != c) {
            if (run & 1)
                out.insert(out.end(), {b, a, c});
            else
                out.insert(out.end(), {a, b, c});
        }
        a = b;
        b = c;
        ++run;
    }
}

}  // namespace

Mesh readPly(const std::string& file, const PlyHeader& h) {
    PlyData data(file, h);
    Mesh m;
    m.source = file;
    const uint64_t nv = h.count("vertex");
    if (nv > uint64_t(UINT32_MAX)) throw Error(file, "more than 2^32 vertices");
    for (const PlyElement& e : h.elements) {
        if (e.name == "vertex") {
            int px = -1, py = -1, pz = -1, nx = -1, ny = -1, nz = -1, cr = -1, cg = -1, cb = -1, tu = -1, tv = -1;
            for (int i = 0; i < int(e.props.size()); ++i) {
                const std::string& n = e.props[size_t(i)].name;
                if (e.props[size_t(i)].isList) continue;
                if (n == "x")
                    px = i;
                else if (n == "y")
                    py = i;
                else if (n == "z")
                    pz = i;
                else if (n == "nx")
                    nx = i;
                else if (n == "ny")
                    ny = i;
                else if (n == "nz")
                    nz = i;
                else if (n == "red" || n == "r")
                    cr = i;
                else if (n == "green" || n == "g")
                    cg = i;
                else if (n == "blue" || n == "b")
                    cb = i;
                else if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s")
                    tu = i;
                else if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t")
                    tv = i;
            }
            if (px < 0 || py < 0 || pz < 0) throw Error(file, "PLY vertex element lacks x, y or z");
            const bool hasN = nx >= 0 && ny >= 0 && nz >= 0, hasC = cr >= 0 && cg >= 0 && cb >= 0,
                       hasT = tu >= 0 && tv >= 0;
            m.positions.resize(size_t(e.count));
            if (hasN) m.normals.resize(size_t(e.count));
            if (hasC) m.colors.resize(size_t(e.count));
            if (hasT) m.uvs.resize(2 * size_t(e.count));
            const float colorScale = hasC && e.props[size_t(cr)].typeKind != 'f' ? 1.0f / 255.0f : 1.0f;
            std::vector<double> v(e.props.size());
            for (uint64_t k = 0; k < e.count; ++k) {
                for (size_t i = 0; i < e.props.size(); ++i) {
                    const PlyProperty& p = e.props[i];
                    if (p.isList) {
                        data.skipList(p, data.listLength(p, Where{e.name, k}));
                        continue;
                    }
                    v[i] = data.value(p.typeKind, p.typeBytes);
                }
                m.positions[k] = {float(v[size_t(px)]), float(v[size_t(py)]), float(v[size_t(pz)])};
                if (hasN)
                    m.normals[k] = normalize(Vec3f{float(v[size_t(nx)]), float(v[size_t(ny)]), float(v[size_t(nz)])});
                if (hasC)
                    m.colors[k] = Vec3f{float(v[size_t(cr)]), float(v[size_t(cg)]), float(v[size_t(cb)])} * colorScale;
                if (hasT) {
                    m.uvs[2 * k] = float(v[size_t(tu)]);
                    m.uvs[2 * k + 1] = float(v[size_t(tv)]);
                }
            }
        } else if (isPlyFaceElement(e.name)) {
            const PlyProperty* idx = plyIndexList(e);
            const bool strips = e.name == "tristrips";
            for (uint64_t k = 0; k < e.count; ++k) {
                for (const PlyProperty& p : e.props) {
                    if (!p.isList) {
                        data.value(p.typeKind, p.typeBytes);
                        continue;
                    }
                    const Where where{e.name, k};
                    const uint64_t c = data.listLength(p, where);
                    if (&p != idx)
                        data.skipList(p, c);
                    else if (strips)
                        readStrip(data, p, c, nv, where, m.indices);
                    else
                        readPolygon(data, p, c, nv, where, m.indices);
                }
            }
        } else {
            // Other elements are skipped value by value (sizes may vary with lists).
            for (uint64_t k = 0; k < e.count; ++k)
                for (const PlyProperty& p : e.props) {
                    if (!p.isList) {
                        data.value(p.typeKind, p.typeBytes);
                        continue;
                    }
                    data.skipList(p, data.listLength(p, Where{e.name, k}));
                }
        }
    }
    return m;
}

}  // namespace rtfact
