// The scalar decoder shared by PLY, PCD and the volume readers: every type, both byte
// orders, and the PLY type spellings.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "core/io/scalar_type.h"

using namespace rtfact::io;

namespace {

// The bytes of `v` in little- and big-endian order, whatever the host.
template <class T>
std::pair<std::string, std::string> encode(T v) {
    std::string native(sizeof(T), '\0');
    std::memcpy(native.data(), &v, sizeof(T));
    std::string reversed(native.rbegin(), native.rend());
    return std::endian::native == std::endian::little ? std::pair{native, reversed} : std::pair{reversed, native};
}

template <class T>
void expectDecodes(ScalarType t, T v) {
    SCOPED_TRACE(scalarTypeName(t));
    ASSERT_EQ(scalarBytes(t), int(sizeof(T)));
    const auto [le, be] = encode(v);
    EXPECT_EQ(decodeScalar(le.data(), t, false), double(v));
    EXPECT_EQ(decodeScalar(be.data(), t, true), double(v));
    EXPECT_EQ(loadScalar<T>(le.data(), false), v);
    EXPECT_EQ(loadScalar<T>(be.data(), true), v);
    // Unaligned reads.
    const std::string shifted = "x" + be;
    EXPECT_EQ(decodeScalar(shifted.data() + 1, t, true), double(v));
}

}  // namespace

TEST(ScalarType, EveryTypeInBothByteOrders) {
    expectDecodes<int8_t>(ScalarType::I8, -100);
    expectDecodes<uint8_t>(ScalarType::U8, 200);
    expectDecodes<int16_t>(ScalarType::I16, -12345);
    expectDecodes<uint16_t>(ScalarType::U16, 54321);
    expectDecodes<int32_t>(ScalarType::I32, -123456789);
    expectDecodes<uint32_t>(ScalarType::U32, 4000000000u);
    expectDecodes<float>(ScalarType::F32, -1.5e-3f);
    expectDecodes<double>(ScalarType::F64, 2.25e100);
}

// The wrong byte order gives a different value (the decoder really swaps).
TEST(ScalarType, ByteOrderMatters) {
    const unsigned char b[4] = {0x01, 0x02, 0x03, 0x04};
    EXPECT_EQ(decodeScalar(b, ScalarType::U32, false), double(0x04030201u));
    EXPECT_EQ(decodeScalar(b, ScalarType::U32, true), double(0x01020304u));
    EXPECT_EQ(decodeScalar(b, ScalarType::I16, true), double(0x0102));
    EXPECT_EQ(decodeScalar(b, ScalarType::U8, true), 1.0);
    const unsigned char m[2] = {0xff, 0xfe};
    EXPECT_EQ(decodeScalar(m, ScalarType::I16, true), -2.0);
    EXPECT_EQ(decodeScalar(m, ScalarType::I16, false), double(int16_t(0xfeff)));
}

TEST(ScalarType, PlySpellingsAndProperties) {
    const std::pair<const char*, ScalarType> names[] = {
        {"char", ScalarType::I8},     {"int8", ScalarType::I8},     {"uchar", ScalarType::U8},
        {"uint8", ScalarType::U8},    {"short", ScalarType::I16},   {"int16", ScalarType::I16},
        {"ushort", ScalarType::U16},  {"uint16", ScalarType::U16},  {"int", ScalarType::I32},
        {"int32", ScalarType::I32},   {"uint", ScalarType::U32},    {"uint32", ScalarType::U32},
        {"float", ScalarType::F32},   {"float32", ScalarType::F32}, {"double", ScalarType::F64},
        {"float64", ScalarType::F64},
    };
    for (const auto& [n, t] : names) {
        SCOPED_TRACE(n);
        ASSERT_TRUE(parsePlyScalarType(n).has_value());
        EXPECT_EQ(*parsePlyScalarType(n), t);
    }
    for (const char* bad : {"", "float16", "int64", "Float", "list", "uchar "}) EXPECT_FALSE(parsePlyScalarType(bad));
    int floats = 0, unsignedTypes = 0;
    for (const ScalarType t : kAllScalarTypes) {
        floats += isFloatType(t);
        unsignedTypes += isUnsignedType(t);
        EXPECT_EQ(std::string(scalarTypeName(t)).substr(1), std::to_string(8 * scalarBytes(t)));
    }
    EXPECT_EQ(floats, 2);
    EXPECT_EQ(unsignedTypes, 3);
    EXPECT_STREQ(scalarTypeName(ScalarType::U16), "u16");
    EXPECT_STREQ(scalarTypeName(ScalarType::F64), "f64");
}
