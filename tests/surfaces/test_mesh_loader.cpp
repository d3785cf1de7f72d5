// Mesh loaders on good files of every format and on truncated, malformed and hostile
// ones: every bad file must give a one-line rtfact::Error, never a crash or a huge
// allocation; the CLI turns it into "rtfact: error: <file>: <what>" and exit code 1.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>

#include "core/util/error.h"
#include "surfaces/mesh_loader.h"
#include "tests/common/image_compare.h"

using namespace rtfact;
using namespace rtfact::surfaces;
namespace fs = std::filesystem;

namespace {

std::string dir() {
    static const std::string d = [] {
        const std::string p = test::testOutDir() + "/surfaces_loader";
        fs::create_directories(p);
        return p;
    }();
    return d;
}

std::string write(const std::string& name, const std::string& bytes) {
    const std::string p = dir() + "/" + name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p;
}

const char* kCubeVerts = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
const char* kCubeFaces = "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n";

std::string asciiPly() {
    return std::string(
               "ply\nformat ascii 1.0\ncomment unit cube\nelement vertex 8\nproperty float x\nproperty float y\n"
               "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n") +
           kCubeVerts + kCubeFaces;
}

std::string binaryPly(uint32_t faceCountInHeader, bool truncate) {
    std::string h =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face " +
        std::to_string(faceCountInHeader) + "\nproperty list uchar int vertex_indices\nend_header\n";
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    h.append(reinterpret_cast<const char*>(v), sizeof(v));
    h.push_back(char(3));
    const int32_t idx[3] = {0, 1, 2};
    h.append(reinterpret_cast<const char*>(idx), sizeof(idx));
    if (truncate) h.resize(h.size() - 30);
    return h;
}

// Loads a bad file and checks the error is a clear single line naming the file.
void expectError(const std::string& path, const std::string& needle = "", std::string file = "") {
    try {
        loadMesh(path);
        FAIL() << path << " loaded without error";
    } catch (const Error& e) {
        EXPECT_EQ(e.file(), file.empty() ? path : file);
        const std::string msg = e.what();
        EXPECT_FALSE(msg.empty());
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "multi-line error: " << msg;
        if (!needle.empty()) {
            EXPECT_NE(msg.find(needle), std::string::npos) << "message: " << msg;
        }
    }
}

}  // namespace

TEST(MeshLoader, AsciiPlyQuadsAreTriangulatedWithNormals) {
    const Mesh m = loadMesh(write("cube_ascii.ply", asciiPly()));
    EXPECT_EQ(m.positions.size(), 8u);
    EXPECT_EQ(m.triangles(), 12u);
    EXPECT_TRUE(m.normalsComputed);
    ASSERT_EQ(m.normals.size(), 8u);
    // The corner normal of a closed cube points away from the centre.
    EXPECT_LT(dot(m.normals[0], Vec3f(1, 1, 1)), 0.0f);
    EXPECT_EQ(m.bounds().lo, Vec3f(0.0f));
    EXPECT_EQ(m.bounds().hi, Vec3f(1.0f));
}

TEST(MeshLoader, BinaryPly) {
    const Mesh m = loadMesh(write("tri_binary.ply", binaryPly(1, false)));
    EXPECT_EQ(m.triangles(), 1u);
}

TEST(MeshLoader, ObjWithMtlMaterialsAndUVs) {
    write("two.mtl", "newmtl red\nKd 1 0 0\nnewmtl glass\nKd 1 1 1\nNi 1.5\nd 0.1\nmap_Kd tex.png\n");
    const std::string p = write("two.obj",
                                "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                "vn 0 0 1\nusemtl red\nf 1/1/1 2/2/1 3/3/1\nusemtl glass\nf -4/4/1 -2/3/1 -1/4/1\n");
    const Mesh m = loadMesh(p);
    EXPECT_EQ(m.triangles(), 2u);
    ASSERT_EQ(m.materials.size(), 2u);
    EXPECT_EQ(m.materials[0].name, "red");
    EXPECT_EQ(m.materials[0].kd, Vec3f(1, 0, 0));
    EXPECT_FLOAT_EQ(m.materials[1].ior, 1.5f);
    EXPECT_NE(m.materials[1].diffuseMap.find("tex.png"), std::string::npos);
    EXPECT_EQ(m.materialIds, (std::vector<int32_t>{0, 1}));
    EXPECT_FALSE(m.uvs.empty());
    EXPECT_FALSE(m.normalsComputed);
}

TEST(MeshLoader, StlAsciiAndBinary) {
    const Mesh a = loadMesh(write("tri_ascii.stl",
                                  "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                  "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n"));
    EXPECT_EQ(a.triangles(), 1u);
    std::string b(80, ' ');
    const uint32_t n = 1;
    b.append(reinterpret_cast<const char*>(&n), 4);
    const float f[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    b.append(reinterpret_cast<const char*>(f), sizeof(f));
    b.append(2, '\0');
    EXPECT_EQ(loadMesh(write("tri_binary.stl", b)).triangles(), 1u);
}

TEST(MeshLoader, VtkLegacyAndVtp) {
    const Mesh a = loadMesh(write("tri.vtk",
                                  "# vtk DataFile Version 3.0\ntri\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n"
                                  "0 0 0 1 0 0 1 1 0 0 1 0\nPOLYGONS 1 5\n4 0 1 2 3\n"));
    EXPECT_EQ(a.triangles(), 2u);
    const Mesh b = loadMesh(write("tri.vtp", R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">
<PolyData><Piece NumberOfPoints="3" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="1">
<Points><DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 0 1 0</DataArray></Points>
<Polys><DataArray type="Int32" Name="connectivity" format="ascii">0 1 2</DataArray>
<DataArray type="Int32" Name="offsets" format="ascii">3</DataArray></Polys>
</Piece></PolyData></VTKFile>
)"));
    EXPECT_EQ(b.triangles(), 1u);
}

TEST(MeshLoader, SeveralFilesMerge) {
    const std::string a = write("m1.ply", asciiPly()), b = write("m2.ply", binaryPly(1, false));
    const Mesh m = loadMeshes({a, b});
    EXPECT_EQ(m.triangles(), 13u);
    EXPECT_EQ(m.positions.size(), 11u);
    m.validate();
}

TEST(MeshLoader, KindDetection) {
    EXPECT_EQ(meshFileKind(write("k.ply", asciiPly())), MeshFileKind::Ply);
    // A PLY without faces is a point cloud: not ours.
    EXPECT_EQ(meshFileKind(write("pts.ply",
                                 "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                                 "property float z\nend_header\n0 0 0\n")),
              MeshFileKind::NotMesh);
    EXPECT_EQ(meshFileKind(write("vol.vtk", "# vtk DataFile Version 3.0\nv\nASCII\nDATASET STRUCTURED_POINTS\n")),
              MeshFileKind::NotMesh);
    EXPECT_EQ(meshFileKind("x.txt"), MeshFileKind::NotMesh);
}

TEST(MeshLoader, MalformedFilesGiveClearErrors) {
    expectError(dir() + "/does_not_exist.ply", "no such file");
    expectError(write("empty.ply", ""), "empty");
    expectError(write("trunc.ply", binaryPly(1, true)), "truncated");
    expectError(write("lying.ply", binaryPly(1000000000u, false)), "lying");
    expectError(write("nohead.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"), "end_header");
    expectError(write("badtype.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n0\n"),
                "type");
    expectError(write("points.ply",
                      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n0 0 0\n"),
                "no faces");
    expectError(write("nan.ply",
                      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                      "0 0 0\nnan 1 0\n0 1 0\n3 0 1 2\n"),
                "NaN");
    expectError(write("range.ply",
                      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"),
                "vertex");
    expectError(write("bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 9\n"), "out of range");
    expectError(write("noface.obj", "v 0 0 0\nv 1 0 0\n"), "no faces");
    expectError(write("badnum.obj", "v 0 zero 0\n"), "line 1");
    expectError(write("missing_mtl.obj", "mtllib nope.mtl\nv 0 0 0\n"), "material library", dir() + "/nope.mtl");
    std::string stl(80, ' ');
    const uint32_t n = 100000000u;
    stl.append(reinterpret_cast<const char*>(&n), 4);
    expectError(write("lying.stl", stl + std::string(50, '\0')), "STL");
    expectError(write("lying.vtk", "# vtk DataFile Version 3.0\nx\nBINARY\nDATASET POLYDATA\nPOINTS 900000000 float\n"),
                "lying");
    expectError(write("lying_polys.vtk",
                      "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\n"
                      "POLYGONS 900000000 900000000\n3 0 1 2\n"),
                "lying");
    expectError(write("notvtk.vtk", "hello\n"), "VTK");
    expectError(write("lying.vtp",
                      "<VTKFile type=\"PolyData\"><PolyData><Piece NumberOfPoints=\"999999999999\" "
                      "NumberOfPolys=\"1\"></Piece></PolyData></VTKFile>"),
                "VTP");
    expectError(write("garbage.vtp",
                      "<VTKFile type=\"PolyData\"><PolyData><Piece NumberOfPoints=\"3\" NumberOfPolys=\"1\">"
                      "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0"));
    expectError(write("unknown.xyz3", "1 2 3\n"), "unknown mesh format");
    // Corrupted binary face list (count byte 3 -> 200): VTK's PLY reader crashed here.
    std::string corrupt = binaryPly(1, false);
    corrupt[corrupt.size() - 13] = char(200);
    expectError(write("corrupt_list.ply", corrupt), "truncated");
    // Out-of-range index in binary data.
    std::string badIdx = binaryPly(1, false);
    badIdx[badIdx.size() - 1] = char(0x7f);
    expectError(write("bad_index.ply", badIdx), "refers to vertex");
    // Wrong magic, negative counts, infinite coordinates, the wrong byte order.
    expectError(write("magic.ply", "plx\nformat ascii 1.0\nelement vertex 3\nend_header\n"), "");
    expectError(write("negative.ply", "ply\nformat ascii 1.0\nelement vertex -3\nproperty float x\nend_header\n"), "");
    expectError(write("inf.ply",
                      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                      "0 0 0\ninf 1 0\n0 1 0\n3 0 1 2\n"),
                "NaN");
    std::string swapped = binaryPly(1, false);
    swapped.replace(swapped.find("little"), 6, "big");  // indices read as 0x01000000...
    expectError(write("big_endian.ply", swapped), "");
    expectError(write("inf.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"), "");
    expectError(write("zero_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), "line 4");
    expectError(write("negative_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -9 1 2\n"), "line 4");
    std::string zeroStl(80, ' ');
    zeroStl.append(4, '\0');
    expectError(write("zero.stl", zeroStl), "");
    std::string nanStl(80, ' ');
    const uint32_t one = 1;
    nanStl.append(reinterpret_cast<const char*>(&one), 4);
    const float tri[12] = {0, 0, 1, 0, 0, 0, std::numeric_limits<float>::infinity(), 0, 0, 0, 1, 0};
    nanStl.append(reinterpret_cast<const char*>(tri), sizeof(tri));
    nanStl.append(2, '\0');
    expectError(write("inf.stl", nanStl), "");
    expectError(write("facets.stl", "solid x\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0\n"), "");
    for (const char* ext : {".ply", ".obj", ".stl", ".vtk", ".vtp"}) {
        const std::string d = dir() + "/a_directory" + ext;
        fs::create_directories(d);
        expectError(d, "directory");
    }
    // Legacy VTK cell lists are checked by us before VTK reads them (it segfaulted on these).
    const std::string vtkHead =
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\n";
    expectError(write("short_polys.vtk", vtkHead + "POLYGONS 2 8\n3 0 1 2\n"), "truncated");
    expectError(write("bad_cell.vtk", vtkHead + "POLYGONS 1 4\n4 0 1 2\n"), "declares 4 points");
    expectError(write("bad_vtk_index.vtk", vtkHead + "POLYGONS 1 4\n3 0 1 7\n"), "refers to point 7");
    expectError(write("bad_section.vtk", vtkHead + "POLYGONZ 1 4\n3 0 1 2\n"), "unsupported legacy VTK section");
    // VTK legacy with fewer coordinates than declared: VTK only warns, we fail.
    expectError(write("short.vtk",
                      "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0\n"
                      "POLYGONS 1 4\n3 0 1 2\n"));
}

// A named pipe blocks whoever opens it until a writer comes: every mesh input (and an
// MTL library) is refused before it is opened, and meshFileKind does not look inside.
// A reader stuck on the pipe fails the test instead of hanging it: after 10 s a writer
// opens and closes the pipe, so the reader sees an empty file and returns.
template <class F>
void withoutBlocking(const std::string& fifo, F&& f) {
    auto run = std::async(std::launch::async, std::forward<F>(f));
    if (run.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
        ADD_FAILURE() << "blocked on the named pipe " << fifo;
        const int fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
        if (fd >= 0) close(fd);
    }
    run.get();
}

std::string makeFifo(const std::string& path) {
    fs::remove(path);
    EXPECT_EQ(mkfifo(path.c_str(), 0600), 0) << path;
    return path;
}

TEST(MeshLoader, NamedPipesAreRefusedWithoutOpening) {
    for (const char* ext : {".ply", ".obj", ".stl", ".vtk", ".vtp"}) {
        const std::string fifo = makeFifo(dir() + "/pipe" + ext);
        withoutBlocking(fifo, [&] { EXPECT_NE(meshFileKind(fifo), MeshFileKind::NotMesh); });
        withoutBlocking(fifo, [&] { expectError(fifo, "named pipe"); });
    }
    const std::string mtl = makeFifo(dir() + "/pipe_lib.mtl");
    const std::string obj = write("pipe_mtl.obj", "mtllib pipe_lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    withoutBlocking(mtl, [&] { expectError(obj, "named pipe", mtl); });
}

// The CLI: one line "rtfact: error: <file>: <what>" and exit code 1.
TEST(MeshLoader, CliReportsErrorAndExitsOne) {
    const std::string cli = RTFACT_CLI;
    // The build makes rtfact before this test binary (tests/surfaces/CMakeLists.txt).
    ASSERT_TRUE(fs::exists(cli)) << "rtfact binary missing: " << cli;
    const std::string bad = write("cli_lying.ply", binaryPly(1000000000u, false));
    const std::string errFile = dir() + "/cli_stderr.txt";
    const std::string cmd = "'" + cli + "' mesh '" + bad + "' -o '" + dir() + "/cli.png' --quiet 2> '" + errFile + "'";
    const int rc = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(rc));
    EXPECT_EQ(WEXITSTATUS(rc), 1);
    std::ifstream in(errFile);
    std::string line, rest;
    std::getline(in, line);
    EXPECT_EQ(line.rfind("rtfact: error: " + bad + ": ", 0), 0u) << line;
    EXPECT_FALSE(std::getline(in, rest)) << "more than one line: " << rest;
}
