// PLY data reader (ASCII, binary little/big endian). Ours rather than VTK's: vtkPLYReader
// crashes on corrupted face lists (found by flipping bytes of a real file), and every
// count and index here is checked against the bytes actually present.
#include "surfaces/ply_reader.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/util/error.h"

namespace rtfact::surfaces {

namespace {

// Which element entry is being read, for messages only (built when one is needed).
struct Where {
    const std::string& element;
    uint64_t k;
    std::string str() const { return element + " " + std::to_string(k); }
};

class PlyData {
   public:
    PlyData(const io::MappedFile& f, const io::PlyHeader& h)
        : file_(f.name()), h_(h), buf_(f.bytes().substr(size_t(h.headerBytes))) {}
    double value(io::ScalarType t) {
        if (h_.ascii()) return asciiValue();
        const size_t bytes = size_t(io::scalarBytes(t));
        if (pos_ + bytes > buf_.size()) throw Error(file_, "truncated PLY data (premature end of file)");
        const double v = io::decodeScalar(buf_.data() + pos_, t, h_.bigEndian());
        pos_ += bytes;
        return v;
    }

    // A list's length, checked against the bytes left, so that a corrupt count can drive
    // neither a long loop nor an allocation.
    uint64_t listLength(const io::PlyProperty& p, const Where& where) {
        const double c = value(p.countType);
        if (!(c >= 0) || c != std::floor(c)) throw Error(file_, where.str() + ": bad list length " + number(c));
        // Binary values take their size; ASCII ones a character and a separator (but the last).
        const double fits = ascii() ? double(remaining() + 1) / 2 : double(remaining()) / io::scalarBytes(p.type);
        if (c > fits)
            throw Error(file_, "truncated or corrupt PLY data: " + where.str() + " lists " + number(c) +
                                   " values but only " + std::to_string(remaining()) + " bytes are left");
        return uint64_t(c);
    }
    void skipList(const io::PlyProperty& p, uint64_t n) {
        for (uint64_t j = 0; j < n; ++j) value(p.type);
    }
    bool ascii() const { return h_.ascii(); }
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
    const io::PlyHeader& h_;
    std::string_view buf_;  // the body, in the mapped file
    size_t pos_ = 0;
};

// One vertex index of a face or strip: an integer below the vertex count.
uint32_t vertexIndex(const std::string& file, double x, uint64_t nv, const Where& where) {
    if (!(x >= 0 && x < double(nv)) || x != std::floor(x))
        throw Error(file, where.str() + " refers to vertex " + PlyData::number(x) + " of " + std::to_string(nv));
    return uint32_t(x);
}

// A polygon of n vertices, fanned from its first; degenerate triangles are dropped.
void readPolygon(PlyData& data, const io::PlyProperty& p, uint64_t n, uint64_t nv, const Where& where,
                 std::vector<uint32_t>& out) {
    uint32_t first = 0, prev = 0;
    for (uint64_t j = 0; j < n; ++j) {
        const uint32_t id = vertexIndex(data.file(), data.value(p.type), nv, where);
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
void readStrip(PlyData& data, const io::PlyProperty& p, uint64_t n, uint64_t nv, const Where& where,
               std::vector<uint32_t>& out) {
    const double restartU =
        io::isUnsignedType(p.type) && !data.ascii() ? std::ldexp(1.0, 8 * io::scalarBytes(p.type)) - 1 : -1;
    uint64_t run = 0;  // indices in the current strip
    uint32_t a = 0, b = 0;
    for (uint64_t j = 0; j < n; ++j) {
        const double x = data.value(p.type);
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

Mesh readPly(const io::MappedFile& f, const io::PlyHeader& h) {
    const std::string& file = f.name();
    PlyData data(f, h);
    Mesh m;
    m.source = file;
    const uint64_t nv = h.count("vertex");
    if (nv > uint64_t(UINT32_MAX)) throw Error(file, "more than 2^32 vertices");
    for (const io::PlyElement& e : h.elements) {
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
            const float colorScale = hasC && !io::isFloatType(e.props[size_t(cr)].type) ? 1.0f / 255.0f : 1.0f;
            std::vector<double> v(e.props.size());
            for (uint64_t k = 0; k < e.count; ++k) {
                for (size_t i = 0; i < e.props.size(); ++i) {
                    const io::PlyProperty& p = e.props[i];
                    if (p.isList) {
                        data.skipList(p, data.listLength(p, Where{e.name, k}));
                        continue;
                    }
                    v[i] = data.value(p.type);
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
            const io::PlyProperty* idx = plyIndexList(e);
            const bool strips = e.name == "tristrips";
            for (uint64_t k = 0; k < e.count; ++k) {
                for (const io::PlyProperty& p : e.props) {
                    if (!p.isList) {
                        data.value(p.type);
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
                for (const io::PlyProperty& p : e.props) {
                    if (!p.isList) {
                        data.value(p.type);
                        continue;
                    }
                    data.skipList(p, data.listLength(p, Where{e.name, k}));
                }
        }
    }
    return m;
}

bool isPlyFaceElement(const std::string& element) { return element == "face" || element == "tristrips"; }

const io::PlyProperty* plyIndexList(const io::PlyElement& e) {
    for (const io::PlyProperty& p : e.props)
        if (p.isList && (p.name == "vertex_indices" || p.name == "vertex_index")) return &p;
    return nullptr;
}

bool plyHasFaces(const io::PlyHeader& h) {
    for (const io::PlyElement& e : h.elements)
        if (isPlyFaceElement(e.name) && e.count > 0 && plyIndexList(e)) return true;
    return false;
}

uint64_t plyTriangleEstimate(const io::PlyHeader& h) {
    const bool ascii = h.ascii();
    uint64_t faces = 0, otherBytes = 0;
    int stripIndexBytes = 0;
    for (const io::PlyElement& e : h.elements) {
        const io::PlyProperty* idx = plyIndexList(e);
        if (e.name == "face") faces += e.count;
        // ASCII: most indices of n vertices have about as many digits as n - 1 (the
        // vertices' own bytes count as 2 per value, so the rest is generous anyway).
        if (e.name == "tristrips" && idx)
            stripIndexBytes =
                ascii ? 1 + std::max<int>(1, int(std::to_string(std::max<uint64_t>(h.count("vertex"), 1) - 1).size()))
                      : io::scalarBytes(idx->type);
        // The same minimum sizes as the header check: counts only for lists.
        uint64_t per = 0;
        for (const io::PlyProperty& p : e.props)
            per += ascii ? 2 : uint64_t(io::scalarBytes(p.isList ? p.countType : p.type));
        otherBytes += per * e.count;
    }
    const uint64_t data = h.fileBytes > h.headerBytes ? h.fileBytes - h.headerBytes : 0;
    const uint64_t strips = stripIndexBytes && data > otherBytes ? (data - otherBytes) / uint64_t(stripIndexBytes) : 0;
    return faces + strips;
}

}  // namespace rtfact::surfaces
