// Textures: checker pattern, bilinear image lookup, and OBJ map_Kd images reaching the
// shading colour of a mesh scene.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "surfaces/mesh_loader.h"
#include "surfaces/mesh_scene.h"
#include "surfaces/textures.h"
#include "tests/common/image_compare.h"

using namespace rtfact;

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
    EXPECT_NEAR(t.sample(0.5f, 0.5f).x, 0.5f, 1e-6f);   // half way
    EXPECT_NEAR(t.sample(0.0f, 0.5f).x, 0.5f, 1e-6f);   // wraps around
}

TEST(Textures, ObjDiffuseMapColoursTheSurface) {
    const std::string dir = test::testOutDir() + "/surfaces_textures";
    std::filesystem::create_directories(dir);
    // 2x2 image: red, green / blue, white (top row first).
    writeImage(dir + "/tex.png", 2, 2, {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1});
    std::ofstream(dir + "/quad.mtl") << "newmtl t\nKd 1 1 1\nmap_Kd tex.png\n";
    std::ofstream(dir + "/quad.obj") << "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
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
