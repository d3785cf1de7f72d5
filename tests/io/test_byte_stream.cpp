// The gzip/zlib byte stream of the volume readers: intact streams (at an offset, several
// members, zero padding), raw reads, and cut or corrupt streams, which must fail naming
// the trailer check rather than return what was decoded so far.
#include <gtest/gtest.h>
#include <zlib.h>

#include <string>
#include <vector>

#include "core/io/byte_stream.h"
#include "tests/common/deflate_bytes.h"
#include "tests/io/io_test_files.h"

using namespace rtfact;
using namespace rtfact::io;
using rtfact::test::deflateBytes;
using rtfact::test::expectIoError;
using rtfact::test::ioTestFile;

namespace {

std::string payload() {
    std::string s;
    for (int i = 0; i < 200000; ++i) s += char('a' + (i * 7919) % 26);
    return s;
}

// Reads `n` decoded bytes at `offset`, then finish().
std::string readAll(const std::string& path, uint64_t offset, size_t n, bool compressed) {
    ByteStream s(path, offset, compressed);
    std::string out(n, '\0');
    s.read(out.data(), n, "test data");
    s.finish();
    return out;
}

}  // namespace

TEST(ByteStream, IntactGzipAndZlibStreams) {
    const std::string data = payload();
    const std::string gz = deflateBytes(data, 31), zl = deflateBytes(data, 15);
    ASSERT_EQ(uint8_t(gz[0]), 0x1f);
    EXPECT_EQ(readAll(ioTestFile("intact.gz", "HEADER" + gz), 6, data.size(), true), data);
    EXPECT_EQ(readAll(ioTestFile("intact.z", zl), 0, data.size(), true), data);
    // skip() drops decoded bytes.
    ByteStream s(ioTestFile("skip.gz", gz), 0, true);
    s.skip(1000, "prefix");
    char c = 0;
    s.read(&c, 1, "one byte");
    EXPECT_EQ(c, data[1000]);
}

TEST(ByteStream, MembersAndZeroPadding) {
    const std::string a = "first member ", b = "second member";
    const std::string two = deflateBytes(a, 31) + deflateBytes(b, 31);
    EXPECT_EQ(readAll(ioTestFile("members.gz", two), 0, a.size() + b.size(), true), a + b);
    EXPECT_EQ(readAll(ioTestFile("padded.gz", two + std::string(512, '\0')), 0, a.size() + b.size(), true), a + b);
    expectIoError([&] { readAll(ioTestFile("junk_after.gz", two + std::string(8, '\0') + "junk"), 0, 26, true); },
                  "unexpected bytes after the end of the compressed data");
}

TEST(ByteStream, CutStreamsFail) {
    const std::string data = payload();
    const std::string gz = deflateBytes(data, 31);
    // All payload bytes present, the 8-byte trailer cut: the read succeeds, finish() fails.
    const std::string noTrailer = ioTestFile("no_trailer.gz", gz.substr(0, gz.size() - 8));
    expectIoError([&] { readAll(noTrailer, 0, data.size(), true); },
                  "truncated compressed data: the file ends before the end of the gzip stream and its "
                  "CRC-32/length trailer");
    // Cut in the middle: the read itself comes short.
    expectIoError([&] { readAll(ioTestFile("half.gz", gz.substr(0, gz.size() / 2)), 0, data.size(), true); },
                  "truncated compressed data");
    const std::string zl = deflateBytes(data, 15);
    expectIoError([&] { readAll(ioTestFile("cut.z", zl.substr(0, zl.size() - 2)), 0, data.size(), true); },
                  "zlib stream and its Adler-32 trailer");
}

TEST(ByteStream, BadTrailersFail) {
    const std::string data = payload();
    std::string gz = deflateBytes(data, 31);
    gz[gz.size() - 8] ^= 0x55;  // CRC-32
    expectIoError([&] { readAll(ioTestFile("bad_crc.gz", gz), 0, data.size(), true); },
                  "corrupt compressed data: CRC-32/length trailer does not match the data");
    gz = deflateBytes(data, 31);
    gz[gz.size() - 1] ^= 0x01;  // ISIZE
    expectIoError([&] { readAll(ioTestFile("bad_length.gz", gz), 0, data.size(), true); },
                  "CRC-32/length trailer does not match");
    std::string zl = deflateBytes(data, 15);
    zl.back() ^= 0x01;
    expectIoError([&] { readAll(ioTestFile("bad_adler.z", zl), 0, data.size(), true); },
                  "Adler-32 trailer does not match");
    // A corrupt deflate body names zlib's own diagnosis.
    std::string body = deflateBytes(data, 31);
    for (size_t i = 20; i < 60; ++i) body[i] = char(0xff);
    expectIoError([&] { readAll(ioTestFile("bad_body.gz", body), 0, data.size(), true); }, "corrupt compressed data");
}

TEST(ByteStream, RawReads) {
    const std::string path = ioTestFile("raw.bin", "0123456789");
    EXPECT_EQ(readAll(path, 3, 4, false), "3456");
    expectIoError([&] { readAll(path, 8, 4, false); }, "truncated test data: needed 4 bytes, got 2");
    expectIoError([&] { ByteStream s(ioTestFile("missing_parent_is_fine.bin", "") + ".none", 0, false); },
                  "no such file or directory");
}
