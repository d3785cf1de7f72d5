// All VTK includes of the surfaces library live in this file.
#include "surfaces/mesh_loader.h"

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkExecutive.h>
#include <vtkLogger.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkSTLReader.h>
#include <vtkSmartPointer.h>
#include <vtkStringOutputWindow.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include "core/io/file_helpers.h"
#include "core/io/mapped_file.h"
#include "core/io/ply_header.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/memory_budget.h"
#include "core/util/vtk_quiet.h"
#include "surfaces/ply_reader.h"
#include "surfaces/vtk_legacy_check.h"

namespace rtfact::surfaces {
namespace fs = std::filesystem;

namespace {

using io::fileSize;
using io::lowerExt;

std::string readPrefix(const std::string& file, size_t n) {
    std::ifstream in(file, std::ios::binary);
    std::string s(n, '\0');
    in.read(s.data(), std::streamsize(n));
    s.resize(size_t(in.gcount()));
    return s;
}

// ---- VTK plumbing ----------------------------------------------------------------

template <class Reader>
vtkPolyData* runReader(Reader* reader, const std::string& file, VtkErrors& errs) {
    QuietVtkOutput quiet;
    errs.observe(reader);
    reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, errs.callback);
    reader->SetFileName(file.c_str());
    reader->Update();
    if (!errs.first.empty()) throw Error(file, errs.first);
    if (const std::string m = quiet.firstMessage(); !m.empty()) throw Error(file, m);
    vtkPolyData* pd = reader->GetOutput();
    if (!pd) throw Error(file, "reader produced no data");
    return pd;
}

Vec3f readVec(vtkDataArray* a, vtkIdType i) {
    double t[3] = {0, 0, 0};
    const int nc = a->GetNumberOfComponents();
    for (int c = 0; c < std::min(nc, 3); ++c) t[c] = a->GetComponent(i, c);
    return {float(t[0]), float(t[1]), float(t[2])};
}

Mesh fromPolyData(vtkPolyData* pd, const std::string& file) {
    Mesh m;
    m.source = file;
    vtkPoints* pts = pd->GetPoints();
    const vtkIdType np = pts ? pts->GetNumberOfPoints() : 0;
    m.positions.resize(size_t(np));
    for (vtkIdType i = 0; i < np; ++i) {
        double p[3];
        pts->GetPoint(i, p);
        m.positions[size_t(i)] = {float(p[0]), float(p[1]), float(p[2])};
    }
    vtkPointData* pdat = pd->GetPointData();
    if (vtkDataArray* n = pdat->GetNormals(); n && n->GetNumberOfTuples() == np && n->GetNumberOfComponents() == 3) {
        m.normals.resize(size_t(np));
        for (vtkIdType i = 0; i < np; ++i) m.normals[size_t(i)] = normalize(readVec(n, i));
    }
    if (vtkDataArray* t = pdat->GetTCoords(); t && t->GetNumberOfTuples() == np && t->GetNumberOfComponents() >= 2) {
        m.uvs.resize(2 * size_t(np));
        for (vtkIdType i = 0; i < np; ++i) {
            m.uvs[2 * size_t(i)] = float(t->GetComponent(i, 0));
            m.uvs[2 * size_t(i) + 1] = float(t->GetComponent(i, 1));
        }
    }
    if (vtkDataArray* c = pdat->GetScalars(); c && c->GetNumberOfTuples() == np && c->GetNumberOfComponents() >= 3) {
        // Colour arrays (PLY red/green/blue) are unsigned char; others are taken as [0,1].
        const float scale = c->GetDataType() == VTK_UNSIGNED_CHAR ? 1.0f / 255.0f : 1.0f;
        m.colors.resize(size_t(np));
        for (vtkIdType i = 0; i < np; ++i) m.colors[size_t(i)] = readVec(c, i) * scale;
    }
    auto addCells = [&](vtkCellArray* cells, bool strips) {
        if (!cells) return;
        vtkIdType n;
        const vtkIdType* ids;
        for (cells->InitTraversal(); cells->GetNextCell(n, ids);) {
            for (vtkIdType k = 0; k < n; ++k)
                if (ids[k] < 0 || ids[k] >= np) throw Error(file, "face refers to a vertex out of range");
            for (vtkIdType k = 2; k < n; ++k) {
                // Polygons are fanned; strips alternate orientation.
                vtkIdType a = strips ? ids[k - 2] : ids[0], b = ids[k - 1], c = ids[k];
                if (strips && (k & 1)) std::swap(a, b);
                if (a == b || b == c || a == c) continue;  // degenerate
                m.indices.push_back(uint32_t(a));
                m.indices.push_back(uint32_t(b));
                m.indices.push_back(uint32_t(c));
            }
        }
    };
    addCells(pd->GetPolys(), false);
    addCells(pd->GetStrips(), true);
    return m;
}

// Peak bytes to load a mesh and build its acceleration structures, from the counts a
// header announces. Measured with `rtfact mesh` (armadillo 29k to turbine blade 199k
// triangles): ~85 B per triangle resident (36-byte triangles, BVH nodes, indices, normals),
// plus whatever copy of the file the reader holds.
uint64_t meshBytes(uint64_t vertices, uint64_t triangles, uint64_t fileCopy) {
    return vertices * 36 + triangles * 100 + fileCopy;
}

void checkMeshMemory(const std::string& file, uint64_t vertices, uint64_t triangles, uint64_t fileCopy) {
    checkMemory(file, meshBytes(vertices, triangles, fileCopy), std::to_string(triangles) + " triangles and their BVH",
                "simplify the mesh, e.g. with vtkQuadricDecimation");
}

// ---- format checks before VTK -------------------------------------------------------

void checkStl(const std::string& file) {
    const uint64_t size = fileSize(file);
    const std::string head = readPrefix(file, 84);
    const bool asciiMagic = head.rfind("solid", 0) == 0;
    if (!asciiMagic || (size >= 84 && head.size() == 84)) {
        if (head.size() < 84) {
            if (!asciiMagic) throw Error(file, "truncated STL (shorter than the 84-byte binary header)");
            return;
        }
        uint32_t n;
        std::memcpy(&n, head.data() + 80, 4);
        const uint64_t need = 84 + 50ull * n;
        if (!asciiMagic && need > size)
            throw Error(file, "truncated or lying binary STL: " + std::to_string(n) + " triangles need " +
                                  std::to_string(need) + " bytes, file has " + std::to_string(size));
        if (!asciiMagic) checkMeshMemory(file, 3ull * n, n, 0);  // VTK keeps unmerged points first
        if (asciiMagic && need == size) return;                  // binary file whose comment starts with "solid"
    }
    if (asciiMagic && size > 0) {
        // ASCII STL: VTK parses it line by line, nothing to pre-allocate.
        const std::string body = readPrefix(file, 4096);
        if (body.find("facet") == std::string::npos && body.find("endsolid") == std::string::npos && size > 84)
            throw Error(file, "ASCII STL without facets");
    }
}

// Legacy .vtk: only POLYDATA is a mesh. Its sections are walked in full before VTK sees
// the file (vtk_legacy_check.cpp): vtkPolyDataReader crashes on cell lists shorter than
// declared.
bool checkVtkLegacy(const std::string& file, bool throwOnBad) {
    (void)fileSize(file);
    const VtkLegacyHeader h = readVtkLegacyHeader(file);
    if (!h.vtk) {
        if (throwOnBad) throw Error(file, "not a VTK legacy file (missing '# vtk DataFile Version' line)");
        return false;
    }
    if (h.dataset != "POLYDATA") {
        if (throwOnBad) {
            const std::string ds = (h.firstKeyword + " " + h.dataset).substr(0, 60);
            std::string shown;
            for (const char c : ds) shown += (c >= 0x20 && c < 0x7f) ? c : '?';
            throw Error(file, "VTK legacy file is not POLYDATA (" + shown + ")");
        }
        return false;
    }
    validateVtkLegacyPolyData(file);
    return true;
}

// VTP: compressed data may legitimately be smaller than the arrays it holds, so the
// announced counts are bounded by a generous multiple of the file size.
void checkVtp(const std::string& file) {
    const uint64_t size = fileSize(file);
    const std::string head = readPrefix(file, 1 << 16);
    if (head.find("<VTKFile") == std::string::npos) throw Error(file, "not a VTK XML file (no <VTKFile> tag)");
    if (head.find("PolyData") == std::string::npos) throw Error(file, "VTK XML file is not PolyData");
    auto attr = [&](const std::string& name) -> long double {
        long double total = 0;
        for (size_t p = head.find(name + "=\""); p != std::string::npos; p = head.find(name + "=\"", p + 1)) {
            const size_t b = p + name.size() + 2;
            const size_t e = head.find('"', b);
            if (e == std::string::npos || e - b > 20) throw Error(file, "bad " + name + " attribute");
            const std::string v = head.substr(b, e - b);
            if (v.empty() || v.find_first_not_of("0123456789") != std::string::npos)
                throw Error(file, "bad " + name + " attribute '" + v + "'");
            total += std::stold(v);
        }
        return total;
    };
    const long double budget = std::max<long double>((long double)size * 64, 1 << 20);
    if (attr("NumberOfPoints") * 12 > budget || attr("NumberOfPolys") * 16 > budget ||
        attr("NumberOfStrips") * 16 > budget)
        throw Error(file, "lying VTP header: announced point/cell counts cannot fit in a file of " +
                              std::to_string(size) + " bytes");
}

// ---- OBJ / MTL ---------------------------------------------------------------------

bool parseFloats(std::string_view s, float* out, int n) {
    const char* p = s.data();
    const char* end = s.data() + s.size();
    for (int i = 0; i < n; ++i) {
        while (p < end && (*p == ' ' || *p == '\t')) ++p;
        auto r = std::from_chars(p, end, out[i]);
        if (r.ec != std::errc()) return false;
        p = r.ptr;
    }
    return true;
}

std::vector<MeshMaterial> readMtl(const std::string& file) {
    try {
        requireRegularFile(file);
    } catch (const Error& e) {
        throw Error(file, std::string("material library ") + e.what());
    }
    std::ifstream in(file);
    if (!in) throw Error(file, "cannot open material library");
    std::vector<MeshMaterial> mats;
    std::string line;
    int lineNo = 0;
    auto bad = [&](const std::string& what) { throw Error(file, "line " + std::to_string(lineNo) + ": " + what); };
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream ls(line);
        std::string kw;
        ls >> kw;
        if (kw.empty() || kw[0] == '#') continue;
        std::string rest;
        std::getline(ls, rest);
        const size_t b = rest.find_first_not_of(" \t");
        rest = b == std::string::npos ? "" : rest.substr(b);
        if (kw == "newmtl") {
            mats.push_back({});
            mats.back().name = rest;
            continue;
        }
        if (mats.empty()) bad("'" + kw + "' before newmtl");
        MeshMaterial& m = mats.back();
        float v[3];
        if (kw == "Kd" || kw == "Ks" || kw == "Ke") {
            if (!parseFloats(rest, v, 3)) bad("expected three numbers after " + kw);
            (kw == "Kd" ? m.kd : kw == "Ks" ? m.ks : m.ke) = {v[0], v[1], v[2]};
        } else if (kw == "Ns" || kw == "Ni" || kw == "d" || kw == "Tr") {
            if (!parseFloats(rest, v, 1) || !std::isfinite(v[0])) bad("expected a number after " + kw);
            if (kw == "Ns")
                m.ns = v[0];
            else if (kw == "Ni")
                m.ior = v[0];
            else if (kw == "d")
                m.dissolve = v[0];
            else
                m.dissolve = 1.0f - v[0];
        } else if (kw == "illum") {
            if (!parseFloats(rest, v, 1)) bad("expected a number after illum");
            m.illum = int(v[0]);
        } else if (kw == "map_Kd") {
            // Options (-s, -o ...) are not supported; the last token is the image.
            const size_t sp = rest.find_last_of(" \t");
            const std::string img = sp == std::string::npos ? rest : rest.substr(sp + 1);
            m.diffuseMap = (fs::path(file).parent_path() / img).string();
        }
    }
    return mats;
}

Mesh readObj(const std::string& file) {
    std::ifstream in(file);
    if (!in) throw Error(file, "cannot open file");
    Mesh m;
    m.source = file;
    std::vector<Vec3f> v, vn;
    std::vector<float> vt;
    // OBJ indexes positions, uvs and normals separately; vertices are unique triples.
    struct Key {
        int p, t, n;
        bool operator==(const Key&) const = default;
    };
    struct KeyHash {
        size_t operator()(const Key& k) const {
            return size_t(k.p) * 73856093u ^ size_t(k.t) * 19349663u ^ size_t(k.n) * 83492791u;
        }
    };
    std::unordered_map<Key, uint32_t, KeyHash> remap;
    std::vector<Key> keys;
    std::unordered_map<std::string, int> matIndex;
    int currentMat = -1;
    std::string line;
    int lineNo = 0;
    auto bad = [&](const std::string& what) { throw Error(file, "line " + std::to_string(lineNo) + ": " + what); };
    std::vector<uint32_t> face;
    bool anyMat = false;
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const size_t b = line.find_first_not_of(" \t");
        if (b == std::string::npos || line[b] == '#') continue;
        const size_t e = line.find_first_of(" \t", b);
        const std::string kw = line.substr(b, e == std::string::npos ? std::string::npos : e - b);
        const std::string_view rest = e == std::string::npos ? std::string_view() : std::string_view(line).substr(e);
        float f[3];
        if (kw == "v") {
            if (!parseFloats(rest, f, 3)) bad("expected three coordinates after v");
            v.push_back({f[0], f[1], f[2]});
        } else if (kw == "vn") {
            if (!parseFloats(rest, f, 3)) bad("expected three numbers after vn");
            vn.push_back(normalize(Vec3f{f[0], f[1], f[2]}));
        } else if (kw == "vt") {
            f[1] = 0.0f;
            if (!parseFloats(rest, f, 1)) bad("expected numbers after vt");
            parseFloats(rest, f, 2);
            vt.push_back(f[0]);
            vt.push_back(f[1]);
        } else if (kw == "f") {
            face.clear();
            std::istringstream ls{std::string(rest)};
            std::string tok;
            while (ls >> tok) {
                int idx[3] = {0, 0, 0};
                size_t pos = 0;
                for (int c = 0; c < 3 && pos <= tok.size(); ++c) {
                    const size_t slash = tok.find('/', pos);
                    const std::string part =
                        tok.substr(pos, slash == std::string::npos ? std::string::npos : slash - pos);
                    if (!part.empty()) {
                        auto r = std::from_chars(part.data(), part.data() + part.size(), idx[c]);
                        if (r.ec != std::errc() || r.ptr != part.data() + part.size())
                            bad("bad face index '" + tok + "'");
                        const int count = c == 0 ? int(v.size()) : c == 1 ? int(vt.size() / 2) : int(vn.size());
                        // 1-based, negative counts from the end.
                        idx[c] = idx[c] < 0 ? count + idx[c] + 1 : idx[c];
                        if (idx[c] < 1 || idx[c] > count) bad("face index '" + tok + "' out of range");
                    } else if (c == 0) {
                        bad("face without a position index");
                    }
                    if (slash == std::string::npos) break;
                    pos = slash + 1;
                }
                const Key k{idx[0] - 1, idx[1] - 1, idx[2] - 1};
                auto [it, inserted] = remap.try_emplace(k, uint32_t(keys.size()));
                if (inserted) keys.push_back(k);
                face.push_back(it->second);
            }
            if (face.size() < 3) bad("face with fewer than 3 vertices");
            for (size_t k = 2; k < face.size(); ++k) {
                m.indices.insert(m.indices.end(), {face[0], face[k - 1], face[k]});
                m.materialIds.push_back(currentMat);
            }
        } else if (kw == "mtllib") {
            std::string name{rest.substr(rest.find_first_not_of(" \t"))};
            const std::string path = (fs::path(file).parent_path() / name).string();
            for (MeshMaterial& mm : readMtl(path)) {
                matIndex[mm.name] = int(m.materials.size());
                m.materials.push_back(mm);
            }
        } else if (kw == "usemtl") {
            const size_t nb = rest.find_first_not_of(" \t");
            const std::string name = nb == std::string::npos ? "" : std::string(rest.substr(nb));
            auto it = matIndex.find(name);
            if (it == matIndex.end()) {
                // Unknown names get a default material so faces keep their grouping.
                MeshMaterial mm;
                mm.name = name;
                it = matIndex.emplace(name, int(m.materials.size())).first;
                m.materials.push_back(mm);
            }
            currentMat = it->second;
            anyMat = true;
        }
        // o, g, s, l, p and unknown keywords are ignored.
    }
    const bool hasT = std::all_of(keys.begin(), keys.end(), [](const Key& k) { return k.t >= 0; }) && !vt.empty();
    const bool hasN = std::all_of(keys.begin(), keys.end(), [](const Key& k) { return k.n >= 0; }) && !vn.empty();
    m.positions.reserve(keys.size());
    for (const Key& k : keys) {
        m.positions.push_back(v[size_t(k.p)]);
        if (hasT) m.uvs.insert(m.uvs.end(), {vt[2 * size_t(k.t)], vt[2 * size_t(k.t) + 1]});
        if (hasN) m.normals.push_back(vn[size_t(k.n)]);
    }
    if (!anyMat) {
        m.materialIds.clear();
        m.materials.clear();
    } else {
        // Faces before the first usemtl use an extra default material.
        bool needDefault = std::any_of(m.materialIds.begin(), m.materialIds.end(), [](int x) { return x < 0; });
        if (needDefault) {
            const int d = int(m.materials.size());
            m.materials.push_back({});
            for (int32_t& x : m.materialIds)
                if (x < 0) x = d;
        }
    }
    if (m.indices.empty() && !v.empty()) throw Error(file, "OBJ file has vertices but no faces");
    return m;
}

}  // namespace

MeshFileKind meshFileKind(const std::string& file) {
    const std::string ext = lowerExt(file);
    // Headers are only looked at in regular files (a named pipe would block the read);
    // anything else with a mesh extension is the loader's to report.
    bool regular = true;
    try {
        requireRegularFile(file);
    } catch (const Error&) {
        regular = false;
    }
    if (ext == ".ply") {
        if (!regular || !io::isPlyFile(file)) return MeshFileKind::Ply;  // let the loader report it
        try {
            const io::PlyHeader h = io::readPlyHeader(io::MappedFile(file));
            return plyHasFaces(h) ? MeshFileKind::Ply : MeshFileKind::NotMesh;
        } catch (const Error&) {
            return MeshFileKind::Ply;  // broken files are reported by the loader
        }
    }
    if (ext == ".obj") return MeshFileKind::Obj;
    if (ext == ".stl") return MeshFileKind::Stl;
    if (ext == ".vtp") return MeshFileKind::Vtp;
    if (ext == ".vtk") {
        if (!regular) return MeshFileKind::VtkLegacy;
        try {
            return checkVtkLegacy(file, false) ? MeshFileKind::VtkLegacy : MeshFileKind::NotMesh;
        } catch (const Error&) {
            return MeshFileKind::VtkLegacy;
        }
    }
    return MeshFileKind::NotMesh;
}

Mesh loadMesh(const std::string& file) {
    requireRegularFile(file);
    if (fileSize(file) == 0) throw Error(file, "empty file");
    const std::string ext = lowerExt(file);
    Mesh m;
    VtkErrors errs;
    if (ext == ".ply") {
        const io::MappedFile f(file);
        const io::PlyHeader h = io::readPlyHeader(f);
        if (!h.find("vertex") || !h.hasProperty("vertex", "x") || !h.hasProperty("vertex", "y") ||
            !h.hasProperty("vertex", "z"))
            throw Error(file, "PLY file has no vertex element with x, y, z");
        if (!plyHasFaces(h)) {
            for (const io::PlyElement& e : h.elements)
                if (isPlyFaceElement(e.name) && e.count > 0 && !plyIndexList(e))
                    throw Error(file, "PLY element '" + e.name + "' has no vertex_indices list");
            throw Error(file, "PLY file has no faces or triangle strips (a point cloud, see `rtfact points`)");
        }
        checkMeshMemory(file, h.count("vertex"), plyTriangleEstimate(h), h.fileBytes - h.headerBytes);
        m = readPly(f, h);
    } else if (ext == ".stl") {
        checkStl(file);
        vtkNew<vtkSTLReader> r;
        r->MergingOn();  // shared vertices, so normals can be smoothed
        m = fromPolyData(runReader(r.Get(), file, errs), file);
    } else if (ext == ".vtk") {
        checkVtkLegacy(file, true);
        vtkNew<vtkPolyDataReader> r;
        m = fromPolyData(runReader(r.Get(), file, errs), file);
    } else if (ext == ".vtp") {
        checkVtp(file);
        vtkNew<vtkXMLPolyDataReader> r;
        m = fromPolyData(runReader(r.Get(), file, errs), file);
    } else if (ext == ".obj") {
        m = readObj(file);
    } else {
        throw Error(file, "unknown mesh format '" + ext + "' (ply, obj, stl, vtk, vtp)");
    }
    m.source = file;
    if (m.indices.empty()) throw Error(file, "file holds no triangles");
    // Formats without counts up front (OBJ, VTK, ASCII STL): check before the BVH build.
    checkMeshMemory(file, m.positions.size(), m.indices.size() / 3, 0);
    if (m.normals.empty()) m.computeNormals();
    m.validate();
    return m;
}

Mesh loadMeshes(const std::vector<std::string>& files) {
    Mesh all;
    for (const std::string& f : files) all.append(loadMesh(f));
    return all;
}

}  // namespace rtfact::surfaces
