// Every loader, fed its shipped real file truncated at many offsets (inside the header and
// inside the body) and with bytes flipped: it must either load something consistent or
// throw rtfact::Error naming the file. A crash, a hang or a foreign exception fails.
// The formats without a shipped file are swept on files generated at run time in
// test_generated_sweeps.cpp; the sweep itself is in sweep.h.
#include <gtest/gtest.h>

#include <filesystem>
#include <utility>
#include <vector>

#include "core/util/error.h"
#include "points/point_cloud_io.h"
#include "surfaces/mesh_loader.h"
#include "sweep.h"
#include "volume/transfer_function.h"
#include "volume/volume_io.h"

namespace fs = std::filesystem;
using namespace rtfact;
using namespace rtfact::surfaces;
using namespace rtfact::reliability;

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

// A directory named like a file of each format, and a missing file of each format: the
// loader of that format rejects it with an Error naming the path (a directory given to
// loadVolume is taken as a DICOM series, which must fail the same way).
TEST(Hostile, DirectoriesAndMissingFiles) {
    volume::VolumeLoadOptions quiet;
    quiet.progress = false;
    const Loader mesh = [](const std::string& p) { (void)loadMesh(p); };
    const Loader cloud = [](const std::string& p) { (void)points::loadPointCloud(p); };
    const Loader vol = [&](const std::string& p) { (void)volume::loadVolume(p, quiet); };
    const Loader tf = [](const std::string& p) { (void)volume::loadTransferFunction(p); };
    const std::vector<std::pair<std::string, std::vector<Loader>>> cases = {
        {".ply", {mesh, cloud}}, {".pcd", {cloud}},  {".xyz", {cloud}}, {".pts", {cloud}}, {".obj", {mesh}},
        {".stl", {mesh}},        {".vtk", {mesh}},   {".vtp", {mesh}},  {".mhd", {vol}},   {".nrrd", {vol}},
        {".nii", {vol}},         {".nii.gz", {vol}}, {".vti", {vol}},   {".vdb", {vol}},   {".json", {tf}}};
    int checked = 0;
    for (const auto& [ext, loaders] : cases) {
        const std::string dir = outDir() + "/a_directory" + ext;
        fs::create_directories(dir);
        const std::string missing = outDir() + "/missing" + ext;
        fs::remove_all(missing);
        for (const std::string& p : {dir, missing}) {
            for (size_t k = 0; k < loaders.size(); ++k) {
                const std::string what = p + " (loader " + std::to_string(k) + ")";
                try {
                    loaders[k](p);
                    ADD_FAILURE() << what << ": accepted";
                } catch (const Error& e) {
                    EXPECT_EQ(e.file(), p) << what << ": " << e.what();
                    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos)
                        << what << ": one line: " << e.what();
                } catch (const std::exception& e) {
                    ADD_FAILURE() << what << ": foreign exception " << e.what();
                }
                ++checked;
            }
        }
    }
    std::printf("[  sweep   ] DirectoriesAndMissingFiles: %d paths checked\n", checked);
}
