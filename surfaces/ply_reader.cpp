// PLY data reader (ASCII, binary little/big endian). Ours rather than VTK's: vtkPLYReader
// crashes on corrupted face lists (found by flipping bytes of a real file), and every
// count and index here is checked against the bytes actually present.
#include <cstring>
#include <fstream>

#include "core/util/error.h"
#include "surfaces/mesh.h"
#include "surfaces/ply_header.h"

namespace rtfact {

namespace {

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

}  // namespace

Mesh readPly(const std::string& file, const PlyHeader& h) {
    PlyData data(file, h);
    Mesh m;
    m.source = file;
    const uint64_t nv = h.count("vertex");
    for (const PlyElement& e : h.elements) {
        if (e.name == "vertex") {
            int px = -1, py = -1, pz = -1, nx = -1, ny = -1, nz = -1, cr = -1, cg = -1, cb = -1, tu = -1, tv = -1;
            for (int i = 0; i < int(e.props.size()); ++i) {
                const std::string& n = e.props[size_t(i)].name;
                if (e.props[size_t(i)].isList) continue;
                if (n == "x") px = i;
                else if (n == "y") py = i;
                else if (n == "z") pz = i;
                else if (n == "nx") nx = i;
                else if (n == "ny") ny = i;
                else if (n == "nz") nz = i;
                else if (n == "red" || n == "r") cr = i;
                else if (n == "green" || n == "g") cg = i;
                else if (n == "blue" || n == "b") cb = i;
                else if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s") tu = i;
                else if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t") tv = i;
            }
            if (px < 0 || py < 0 || pz < 0) throw Error(file, "PLY vertex element lacks x, y or z");
            const bool hasN = nx >= 0 && ny >= 0 && nz >= 0, hasC = cr >= 0 && cg >= 0 && cb >= 0, hasT = tu >= 0 && tv >= 0;
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
                        const double c = data.value(p.countKind, p.countBytes);
                        if (c < 0 || c > 1e6) throw Error(file, "bad list length in PLY vertex data");
                        for (int j = 0; j < int(c); ++j) data.value(p.typeKind, p.typeBytes);
                        continue;
                    }
                    v[i] = data.value(p.typeKind, p.typeBytes);
                }
                m.positions[k] = {float(v[size_t(px)]), float(v[size_t(py)]), float(v[size_t(pz)])};
                if (hasN) m.normals[k] = normalize(Vec3f{float(v[size_t(nx)]), float(v[size_t(ny)]), float(v[size_t(nz)])});
                if (hasC) m.colors[k] = Vec3f{float(v[size_t(cr)]), float(v[size_t(cg)]), float(v[size_t(cb)])} * colorScale;
                if (hasT) {
                    m.uvs[2 * k] = float(v[size_t(tu)]);
                    m.uvs[2 * k + 1] = float(v[size_t(tv)]);
                }
            }
        } else if (e.name == "face") {
            for (uint64_t k = 0; k < e.count; ++k) {
                for (const PlyProperty& p : e.props) {
                    if (!p.isList) {
                        data.value(p.typeKind, p.typeBytes);
                        continue;
                    }
                    const double c = data.value(p.countKind, p.countBytes);
                    if (c < 0 || c > 1e6 || c != double(int64_t(c))) throw Error(file, "bad face vertex count in PLY data");
                    const bool indices = p.name == "vertex_indices" || p.name == "vertex_index";
                    uint32_t first = 0, prev = 0;
                    for (int j = 0; j < int(c); ++j) {
                        const double x = data.value(p.typeKind, p.typeBytes);
                        if (!indices) continue;
                        if (!(x >= 0 && x < double(nv)))
                            throw Error(file, "face " + std::to_string(k) + " refers to vertex " + std::to_string(int64_t(x)) +
                                                  " of " + std::to_string(nv));
                        const uint32_t id = uint32_t(x);
                        // Polygons are fanned; degenerate triangles are dropped.
                        if (j == 0) first = id;
                        else if (j >= 2 && first != prev && prev != id && first != id)
                            m.indices.insert(m.indices.end(), {first, prev, id});
                        prev = id;
                    }
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
                    const double c = data.value(p.countKind, p.countBytes);
                    if (c < 0 || c > 1e6) throw Error(file, "bad list length in PLY element '" + e.name + "'");
                    for (int j = 0; j < int(c); ++j) data.value(p.typeKind, p.typeBytes);
                }
        }
    }
    return m;
}

}  // namespace rtfact
