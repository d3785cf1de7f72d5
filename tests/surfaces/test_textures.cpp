// Textures: checker pattern, bilinear image lookup, and OBJ map_Kd images reaching the
// shading colour of a mesh scene.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/util/error.h"
#include "surfaces/mesh_loader.h"
#include "surfaces/mesh_scene.h"
#include "surfaces/textures.h"
#include "tests/common/image_compare.h"

using namespace rtfact;
using namespace rtfact::surfaces;

TEST(Textures, CheckerAlternates) {
    const CheckerTexture c{Vec3f(1.0f), Vec3f(0.0f), 2.0f};
    Packet<4> u, v;
    const float us[4] = {0.1f, 0.6f, 0.1f, 0.6f}, vs[4] = {0.1f, 0.1f, 0.6f, 0.6f};
    for (int i = 0; i < 4; ++i) {
        u[i] = us[i];
        v[i] = vs[i];
    }
    const Vec3<4> r = c.lookup<4>(u, v, Vec3<4>(Vec3f(0.0f)));
    EXPECT_EQ(r.x[0], 1.0f);
    EXPECT_EQ(r.x[1], 0.0f);
    EXPECT_EQ(r.x[2], 0.0f);
    EXPECT_EQ(r.x[3], 1.0f);
}

TEST(Textures, ImageBilinear) {
    auto im = std::make_shared<Image>();
    im->width = 2;
    im->height = 1;
    im->channels = 3;
    im->pixels = {0, 0, 0, 1, 1, 1};
    const ImageTexture t{im};
    EXPECT_NEAR(t.sample(0.25f, 0.5f).x, 0.0f, 1e-6f);  // texel centre
    EXPECT_NEAR(t.sample(0.75f, 0.5f).x, 1.0f, 1e-6f);
    EXPECT_NEAR(t.sample(0.5f, 0.5f).x, 0.5f, 1e-6f);  // half way
    EXPECT_NEAR(t.sample(0.0f, 0.5f).x, 0.5f, 1e-6f);  // wraps around
}

TEST(Textures, ObjDiffuseMapColoursTheSurface) {
    const std::string dir = test::testOutDir() + "/surfaces_textures";
    std::filesystem::create_directories(dir);
    // 2x2 image: red, green / blue, white (top row first).
    writeImage(dir + "/tex.png", 2, 2, {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1});
    std::ofstream(dir + "/quad.mtl") << "newmtl t\nKd 1 1 1\nmap_Kd tex.png\n";
    std::ofstream(dir + "/quad.obj")
        << "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
           "usemtl t\nf 1/1 2/2 3/3 4/4\n";
    auto mesh = std::make_shared<const Mesh>(loadMesh(dir + "/quad.obj"));
    const MeshScene<BVH<Triangle>> scene(mesh);
    // Rays at the centres of the four texels (uv = 0.25/0.75).
    const float px[4] = {0.25f, 0.75f, 0.25f, 0.75f}, py[4] = {0.75f, 0.75f, 0.25f, 0.25f};
    const Vec3f expect[4] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    for (int i = 0; i < 4; ++i) {
        RayPacket<1> r;
        r.setLane(0, {px[i], py[i], 1.0f}, {0, 0, -1});
        r.commonOrigin = true;
        r.finalize();
        const auto hit = scene.intersect<1>(r, Mask<1>(true));
        ASSERT_GE(int(hit.id), 0);
        const SurfacePoint<1> sp = scene.surface<1>(r, hit, Mask<1>(true));
        const Vec3f c = sp.color.lane(0);
        EXPECT_NEAR(c.x, expect[i].x, 0.02f) << i;
        EXPECT_NEAR(c.y, expect[i].y, 0.02f) << i;
        EXPECT_NEAR(c.z, expect[i].z, 0.02f) << i;
    }
}

// Hostile map_Kd images: every one is an rtfact::Error naming the image, in one line,
// raised while the scene is built (before rendering).
TEST(Textures, HostileImagesAreOneLineErrorsNamingTheImage) {
    namespace fs = std::filesystem;
    const std::string dir = test::testOutDir() + "/surfaces_textures_hostile";
    fs::create_directories(dir);
    writeImage(dir + "/good.png", 2, 2, {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1});
    std::string png;
    {
        std::ifstream f(dir + "/good.png", std::ios::binary);
        png.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    }
    ASSERT_GT(png.size(), 60u);
    struct Case {
        std::string name, bytes;
        bool directory = false;
    };
    std::vector<Case> cases = {
        {"missing.png", "", false},  // not written below
        {"empty.png", "", false},
        {"truncated.png", png.substr(0, png.size() / 2)},
        {"header_only.png", png.substr(0, 33)},
        {"garbage.png", std::string(200, '\x5a')},
        {"wrong_magic.png", "GIF89a" + png.substr(6)},
        {"dir.png", "", true},
        // A PNM whose header claims 100000 x 100000 pixels: rejected before any allocation.
        {"lying.ppm", "P6\n100000 100000\n255\n" + std::string(64, '\0')},
        {"zero.ppm", "P6\n0 4\n255\n"},
        // Float PFM with a NaN texel.
        {"nan.pfm", std::string("Pf\n1 1\n-1.0\n") + std::string("\x00\x00\xc0\x7f", 4)},
    };
    for (const Case& c : cases) {
        const std::string img = dir + "/" + c.name;
        fs::remove_all(img);
        if (c.directory)
            fs::create_directories(img);
        else if (c.name != "missing.png")
            std::ofstream(img, std::ios::binary) << c.bytes;
        std::ofstream(dir + "/quad.mtl") << "newmtl t\nKd 1 1 1\nmap_Kd " << c.name << "\n";
        std::ofstream(dir + "/quad.obj") << "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                                            "usemtl t\nf 1/1 2/2 3/3\n";
        try {
            auto mesh = std::make_shared<const Mesh>(loadMesh(dir + "/quad.obj"));
            const MeshScene<BVH<Triangle>> scene(mesh);
            ADD_FAILURE() << c.name << ": accepted";
        } catch (const Error& e) {
            EXPECT_EQ(fs::path(e.file()).filename().string(), c.name) << e.message();
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << c.name << ": " << e.what();
        } catch (const std::exception& e) {
            ADD_FAILURE() << c.name << ": foreign exception " << e.what();
        }
    }
}
