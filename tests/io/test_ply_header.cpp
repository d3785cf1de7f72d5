// The one PLY header reader of points and meshes: formats, elements, list types, the
// 1 MiB limit, counts against the file size, and hostile headers.
#include <gtest/gtest.h>

#include <string>

#include "core/io/mapped_file.h"
#include "core/io/ply_header.h"
#include "core/util/error.h"
#include "tests/io/io_test_files.h"

using namespace rtfact;
using namespace rtfact::io;
using rtfact::test::expectIoError;

namespace {

PlyHeader parse(const std::string& bytes) { return parsePlyHeader(bytes, bytes.size(), "test.ply"); }

void expectBad(const std::string& bytes, const std::string& needle) {
    SCOPED_TRACE(bytes.substr(0, 200));
    expectIoError([&] { (void)parse(bytes); }, needle);
}

const std::string kXyz = "property float x\nproperty float y\nproperty float z\n";

}  // namespace

TEST(PlyHeader, AsciiElementsAndProperties) {
    const std::string head = "ply\nformat ascii 1.0\ncomment made by hand\nobj_info none\nelement vertex 3\n" + kXyz +
                             "property uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const std::string body = "0 0 0 1\n1 0 0 2\n0 1 0 3\n3 0 1 2\n";
    const PlyHeader h = parse(head + body);
    EXPECT_TRUE(h.ascii());
    EXPECT_EQ(h.formatName(), "ply ascii");
    EXPECT_EQ(h.headerBytes, head.size());
    EXPECT_EQ(h.fileBytes, head.size() + body.size());
    ASSERT_EQ(h.elements.size(), 2u);
    EXPECT_EQ(h.count("vertex"), 3u);
    EXPECT_EQ(h.count("face"), 1u);
    EXPECT_EQ(h.count("edge"), 0u);
    EXPECT_TRUE(h.hasProperty("vertex", "red"));
    EXPECT_FALSE(h.hasProperty("vertex", "green"));
    const PlyElement& v = h.elements[0];
    ASSERT_EQ(v.props.size(), 4u);
    EXPECT_EQ(v.props[0].type, ScalarType::F32);
    EXPECT_EQ(v.props[3].type, ScalarType::U8);
    EXPECT_EQ(v.fixedBytes(), 13u);
    const PlyProperty& list = h.elements[1].props[0];
    EXPECT_TRUE(list.isList);
    EXPECT_EQ(list.name, "vertex_indices");
    EXPECT_EQ(list.countType, ScalarType::U8);
    EXPECT_EQ(list.type, ScalarType::I32);
    EXPECT_EQ(h.elements[1].fixedBytes(), 0u);  // lists have no fixed size
}

TEST(PlyHeader, BinaryFormatsAndListTypes) {
    for (const auto& [fmt, big] : {std::pair{"binary_little_endian", false}, std::pair{"binary_big_endian", true}}) {
        const std::string head = std::string("ply\r\nformat ") + fmt +
                                 " 1.0\r\nelement strip 1\r\nproperty list ushort uint32 vertex_index\r\n"
                                 "property int16 id\r\nend_header\r\n";
        const PlyHeader h = parse(head + std::string(2 + 2, '\0'));  // list length + id
        EXPECT_FALSE(h.ascii());
        EXPECT_EQ(h.bigEndian(), big);
        EXPECT_EQ(h.formatName(), std::string("ply ") + fmt);
        EXPECT_EQ(h.headerBytes, head.size());  // CRLF line ends
        const PlyProperty& p = h.elements[0].props[0];
        EXPECT_EQ(p.countType, ScalarType::U16);
        EXPECT_EQ(p.type, ScalarType::U32);
        EXPECT_EQ(h.elements[0].props[1].type, ScalarType::I16);
    }
}

TEST(PlyHeader, EndHeaderOnlyAsAKeyword) {
    const std::string h1 =
        "ply\nformat ascii 1.0\ncomment no end_header here\nelement vertex 1\n" + kXyz + "end_header\n";
    EXPECT_EQ(parse(h1 + "1 2 3\n").headerBytes, h1.size());
    expectBad("ply\nformat ascii 1.0\nelement vertex 1\n" + kXyz, "PLY header not terminated by end_header");
    expectBad("ply\nformat ascii 1.0\nelement vertex 0\n" + kXyz + "end_header",
              "end_header not followed by a newline");
}

// The header must end within its first 1 MiB; the boundary is exact.
TEST(PlyHeader, OneMebibyteLimit) {
    const std::string tail = "element vertex 1\n" + kXyz + "end_header\n";
    const std::string start = "ply\nformat ascii 1.0\ncomment ";
    const size_t fill = kMaxPlyHeaderBytes - start.size() - 1 - tail.size();
    const std::string atLimit = start + std::string(fill, 'c') + "\n" + tail;
    ASSERT_EQ(atLimit.size(), kMaxPlyHeaderBytes);
    const std::string body = "1 2 3\n";
    EXPECT_EQ(parse(atLimit + body).headerBytes, kMaxPlyHeaderBytes);
    // Through the mapped file the reader sees the same (only the first 1 MiB is parsed).
    const std::string path = rtfact::test::ioTestFile("at_limit.ply", atLimit + body);
    EXPECT_EQ(readPlyHeader(MappedFile(path)).headerBytes, kMaxPlyHeaderBytes);
    const std::string overLimit = start + std::string(fill + 1, 'c') + "\n" + tail;
    expectBad(overLimit + body, "PLY header longer than 1048576 bytes (the limit) before end_header");
    // A giant comment, and a header cut at the limit in the middle of a property line.
    expectBad(start + std::string(3 << 20, 'c') + "\n" + tail + body, "(the limit)");
    // "property float x" starts 6 bytes before the limit: its cut "proper" is not judged.
    const std::string lines = "element vertex 1\n" + kXyz + "end_header\n";
    const size_t n = kMaxPlyHeaderBytes - 6 - 17 - 1 - start.size();
    const std::string cut = start + std::string(n, 'c') + "\n" + lines;
    ASSERT_EQ(cut.substr(kMaxPlyHeaderBytes - 6, 6), "proper");
    expectBad(cut + body, "(the limit)");
}

TEST(PlyHeader, CountsAreCheckedAgainstTheFileSize) {
    const std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n" + kXyz + "end_header\n";
    EXPECT_NO_THROW(parse(head + std::string(36, '\0')));
    expectBad(head + std::string(35, '\0'),
              "truncated or lying PLY header: element 'vertex' declares 3 vertices; the elements up to it need at "
              "least 36 bytes but only 35 bytes follow the header");
    // Lists count their length bytes at least; the face element names itself.
    const std::string faces = "ply\nformat binary_big_endian 1.0\nelement vertex 1\n" + kXyz +
                              "element face 1000000\nproperty list uchar int vertex_indices\nend_header\n";
    expectBad(faces + std::string(12 + 999999, '\0'), "element 'face' declares 1000000 faces");
    EXPECT_NO_THROW(parse(faces + std::string(12 + 1000000, '\0')));
    // ASCII: a digit and a separator per value, the last separator optional.
    const std::string ascii = "ply\nformat ascii 1.0\nelement vertex 2\n" + kXyz + "end_header\n";
    EXPECT_NO_THROW(parse(ascii + "1 2 3 4 5 6"));
    expectBad(ascii + "1 2 3 4 5", "lying PLY header");
    // Counts of a trillion or more, and huge products, are refused without overflow.
    expectBad("ply\nformat binary_little_endian 1.0\nelement vertex 999999999999\n" + kXyz + "end_header\n",
              "declares 999999999999 vertices");
    expectBad("ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n" + kXyz + "end_header\n",
              "bad count '1000000000000' for PLY element 'vertex'");
}

TEST(PlyHeader, HostileHeaders) {
    const std::string v1 = "element vertex 1\n" + kXyz;
    expectBad("", "not a PLY file (missing 'ply' magic)");
    expectBad("plx\nformat ascii 1.0\n", "not a PLY file");
    expectBad("plyformat ascii 1.0\n", "not a PLY file");
    expectBad("ply\n" + v1 + "end_header\n1 2 3\n", "PLY header has no format line");
    expectBad("ply\nformat utf8 1.0\n" + v1 + "end_header\n", "unknown PLY format 'utf8'");
    expectBad("ply\nformat ascii 1.0\nelement vertex -3\n" + kXyz + "end_header\n",
              "bad count '-3' for PLY element 'vertex'");
    expectBad("ply\nformat ascii 1.0\nelement vertex 1e3\n" + kXyz + "end_header\n", "bad count '1e3'");
    expectBad("ply\nformat ascii 1.0\nelement vertex\n" + kXyz + "end_header\n", "bad PLY element line");
    expectBad("ply\nformat ascii 1.0\nelement vertex 1 2\n" + kXyz + "end_header\n", "bad PLY element line");
    expectBad("ply\nformat ascii 1.0\nproperty float x\n" + v1 + "end_header\n", "PLY property before any element");
    expectBad("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n1\n",
              "unknown PLY property type 'float128'");
    expectBad("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar quad idx\nend_header\n1 0\n",
              "unknown PLY property type 'quad'");
    expectBad("ply\nformat ascii 1.0\nelement face 1\nproperty list float int idx\nend_header\n1 0\n",
              "PLY list length type must be an integer");
    expectBad("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar\nend_header\n1 0\n", "bad PLY list property");
    expectBad("ply\nformat ascii 1.0\nelement vertex 1\nproperty float\nend_header\n1\n",
              "PLY property without a name");
    expectBad("ply\nformat ascii 1.0\n" + v1 + "vertex 1 2 3\nend_header\n",
              "unexpected PLY header line 'vertex 1 2 3'");
    expectBad("ply\nformat ascii 1.0\nelement junk 5\nend_header\n" + std::string(100, ' '),
              "PLY element 'junk' declares 5 entries but no properties");
    // Names are one word of at most 255 bytes, without control characters.
    expectBad("ply\nformat ascii 1.0\nelement " + std::string(300, 'v') + " 1\n" + kXyz + "end_header\n1 2 3\n",
              "bad PLY element name 'vvvv");
    expectBad("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\x01\nend_header\n1\n",
              "bad PLY property name 'x?'");
    EXPECT_EQ(parse("ply\nformat ascii 1.0\nelement " + std::string(255, 'v') + " 1\nproperty float x\nend_header\n1\n")
                  .elements[0]
                  .name.size(),
              255u);
    // Binary junk in a line is shown printable and short.
    try {
        (void)parse("ply\nformat ascii 1.0\n\x01\x02" + std::string(500, 'z') + "\nend_header\n");
        FAIL() << "no error";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.find('\x01'), std::string::npos) << m;
        EXPECT_LT(m.size(), 150u) << m;
    }
}

TEST(PlyHeader, MagicCheckOnFiles) {
    EXPECT_TRUE(isPlyFile(rtfact::test::ioTestFile("magic.ply", "ply\nformat ascii 1.0\n")));
    EXPECT_TRUE(isPlyFile(rtfact::test::ioTestFile("magic_cr.ply", "ply\r\n")));
    EXPECT_FALSE(isPlyFile(rtfact::test::ioTestFile("nomagic.ply", "plyx\n")));
    EXPECT_FALSE(isPlyFile(rtfact::test::ioTestFile("short.ply", "ply")));
    EXPECT_FALSE(isPlyFile("/nonexistent/none.ply"));
}
