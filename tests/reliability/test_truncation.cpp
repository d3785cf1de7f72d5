// Every loader, fed its shipped real file truncated at many offsets (inside the header and
// inside the body) and with bytes flipped: it must either load something consistent or
// throw rtfact::Error naming the file. A crash, a hang or a foreign exception fails.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

#include "core/util/error.h"
#include "points/point_cloud_io.h"
#include "surfaces/mesh_loader.h"
#include "volume/transfer_function.h"
#include "volume/volume_io.h"

namespace fs = std::filesystem;
using namespace rtfact;

namespace {

std::string dataset(const std::string& rel) { return std::string(RTFACT_DATASETS) + "/" + rel; }
std::string outDir() {
    const std::string d = std::string(RTFACT_TEST_OUT) + "/reliability";
    fs::create_directories(d);
    return d;
}

std::string readAll(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
void writeAll(const std::string& path, const std::string& bytes) {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
}

// Offsets: every byte of the first 300 (headers), then 40 spread over the body.
std::vector<size_t> cutPoints(size_t size) {
    std::vector<size_t> cuts;
    for (size_t i = 0; i < std::min<size_t>(size, 300); i += 7) cuts.push_back(i);
    for (int k = 1; k < 40; ++k) cuts.push_back(size * size_t(k) / 40);
    return cuts;
}

struct Outcome {
    int loaded = 0, rejected = 0;
};

// Runs `load` on variants of `source`; returns how many loaded and how many were rejected.
Outcome hammer(const std::string& source, const std::string& ext, const std::function<void(const std::string&)>& load) {
    const std::string bytes = readAll(source);
    EXPECT_FALSE(bytes.empty()) << source;
    // One file per test: ctest runs the tests in parallel processes, and truncating a file
    // another process has memory-mapped would kill that process with SIGBUS.
    const std::string path =
        outDir() + "/" + ::testing::UnitTest::GetInstance()->current_test_info()->name() + ext;
    Outcome o;
    auto attempt = [&](const std::string& variant, const std::string& what) {
        writeAll(path, variant);
        try {
            load(path);
            ++o.loaded;
        } catch (const Error& e) {
            ++o.rejected;
            // The error names the file, or the data file its header points to.
            EXPECT_TRUE(e.file() == path || e.file().rfind(outDir(), 0) == 0)
                << what << ": the error must name the file, not '" << e.file() << "'";
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << what << ": one line";
        } catch (const std::exception& e) {
            ADD_FAILURE() << what << ": foreign exception " << e.what();
        }
    };
    for (size_t cut : cutPoints(bytes.size())) attempt(bytes.substr(0, cut), "truncated at " + std::to_string(cut));
    std::mt19937 rng(17);
    for (int k = 0; k < 40; ++k) {
        std::string v = bytes;
        for (int j = 0; j < 4; ++j) v[rng() % std::min<size_t>(v.size(), 4096 + (k % 2) * v.size())] ^= char(1 << (rng() % 8));
        attempt(v, "bytes flipped, variant " + std::to_string(k));
    }
    return o;
}

}  // namespace

TEST(Hostile, MeshPlyTruncatedAndFlipped) {
    const Outcome o = hammer(dataset("meshes/bunny.ply"), ".ply", [](const std::string& p) { (void)loadMesh(p); });
    EXPECT_GT(o.rejected, 40);
}

TEST(Hostile, PointPlyTruncatedAndFlipped) {
    const Outcome o = hammer(dataset("points/bunny_bun000.ply"), ".ply",
                             [](const std::string& p) { (void)points::loadPointCloud(p); });
    EXPECT_GT(o.rejected, 40);
}

TEST(Hostile, VolumeMetaImageHeaderTruncatedAndFlipped) {
    // The header refers to the raw file next to it: copy both.
    fs::copy_file(dataset("volumes/tooth_103x94x161_uint8.raw"), outDir() + "/tooth_103x94x161_uint8.raw",
                  fs::copy_options::overwrite_existing);
    const Outcome o = hammer(dataset("volumes/tooth_103x94x161_uint8.mhd"), ".mhd",
                             [](const std::string& p) { (void)volume::loadVolume(p, {}); });
    EXPECT_GT(o.rejected, 10);
}

TEST(Hostile, VolumeRawTruncated) {
    volume::VolumeLoadOptions opt;
    opt.dims = std::array<int, 3>{103, 94, 161};
    opt.type = "u8";
    opt.progress = false;
    const Outcome o = hammer(dataset("volumes/tooth_103x94x161_uint8.raw"), ".raw",
                             [&](const std::string& p) { (void)volume::loadVolume(p, opt); });
    EXPECT_GT(o.rejected, 40);  // every truncation is a size mismatch
}

TEST(Hostile, TransferFunctionJsonTruncatedAndFlipped) {
    const Outcome o = hammer(dataset("volumes/phantom_translucent_tf.json"), ".json",
                             [](const std::string& p) { (void)volume::loadTransferFunction(p); });
    EXPECT_GT(o.rejected, 10);
}

TEST(Hostile, DirectoriesAndMissingFiles) {
    const std::string dir = outDir() + "/a_directory.ply";
    fs::create_directories(dir);
    EXPECT_THROW((void)loadMesh(dir), Error);
    EXPECT_THROW((void)points::loadPointCloud(dir), Error);
    EXPECT_THROW((void)loadMesh(outDir() + "/missing.obj"), Error);
    EXPECT_THROW((void)points::loadPointCloud(outDir() + "/missing.pcd"), Error);
    EXPECT_THROW((void)volume::loadVolume(outDir() + "/missing.nii.gz", {}), Error);
}
