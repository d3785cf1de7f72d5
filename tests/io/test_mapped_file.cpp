// Mapped files and the small file helpers: regular files only (a named pipe would block
// the open), the bytes as written, and lower-case extensions.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <string>

#include "core/io/file_helpers.h"
#include "core/io/mapped_file.h"
#include "tests/io/io_test_files.h"

using namespace rtfact;
using namespace rtfact::io;
using rtfact::test::expectIoError;
using rtfact::test::ioTestFile;

TEST(MappedFile, MapsRegularFilesOnly) {
    const std::string path = ioTestFile("mapped.bin", std::string("a\0b", 3));
    const MappedFile f(path);
    EXPECT_EQ(f.name(), path);
    ASSERT_EQ(f.size(), 3u);
    EXPECT_EQ(f.bytes(), std::string_view("a\0b", 3));
    const MappedFile empty(ioTestFile("empty.bin", ""));
    EXPECT_EQ(empty.size(), 0u);
    EXPECT_EQ(empty.data(), nullptr);
    expectIoError([] { MappedFile m("/nonexistent/x.ply"); }, "no such file or directory");
    const std::string dir = std::filesystem::path(path).parent_path().string();
    expectIoError([&] { MappedFile m(dir); }, "is a directory");
    const std::string fifo = dir + "/pipe.ply";
    std::filesystem::remove(fifo);
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    expectIoError([&] { MappedFile m(fifo); }, "is a named pipe");
    expectIoError([&] { (void)fileSize(fifo); }, "is a named pipe");
    std::filesystem::remove(fifo);
}

TEST(FileHelpers, LowerExtAndSizes) {
    EXPECT_EQ(lowerExt("dir.D/Scan.PLY"), ".ply");
    EXPECT_EQ(lowerExt("volume.nii.GZ"), ".gz");
    EXPECT_EQ(lowerExt("noext"), "");
    EXPECT_EQ(lower("MET_UShort \xC3\x84"), "met_ushort \xC3\x84");  // bytes >= 0x80 kept
    EXPECT_TRUE(endsWith("a.nii.gz", ".nii.gz"));
    EXPECT_FALSE(endsWith("gz", ".nii.gz"));
    EXPECT_EQ(fileSize(ioTestFile("five.bin", "12345")), 5u);
    expectIoError([] { (void)fileSize("/nonexistent/y.raw"); }, "no such file or directory");
}
