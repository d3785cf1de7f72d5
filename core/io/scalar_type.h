// The scalar types of binary file formats (PLY, PCD, raw/MetaImage/NRRD/NIfTI voxels) and
// their decoding from either byte order. One encoding for every reader.
#pragma once
#include <bit>
#include <concepts>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string_view>

namespace rtfact::io {

enum class ScalarType { I8, U8, I16, U16, I32, U32, F32, F64 };
inline constexpr ScalarType kAllScalarTypes[] = {ScalarType::I8,  ScalarType::U8,  ScalarType::I16, ScalarType::U16,
                                                 ScalarType::I32, ScalarType::U32, ScalarType::F32, ScalarType::F64};

constexpr int scalarBytes(ScalarType t) {
    switch (t) {
        case ScalarType::I8:
        case ScalarType::U8:
            return 1;
        case ScalarType::I16:
        case ScalarType::U16:
            return 2;
        case ScalarType::I32:
        case ScalarType::U32:
        case ScalarType::F32:
            return 4;
        case ScalarType::F64:
            return 8;
    }
    return 0;
}
constexpr bool isFloatType(ScalarType t) { return t == ScalarType::F32 || t == ScalarType::F64; }
constexpr bool isUnsignedType(ScalarType t) {
    return t == ScalarType::U8 || t == ScalarType::U16 || t == ScalarType::U32;
}
// Short name: "u8", "i16", "f32", ... (what `rtfact info` shows as a source type).
const char* scalarTypeName(ScalarType t);
// PLY spellings: char uchar short ushort int uint float double and int8 ... float64.
std::optional<ScalarType> parsePlyScalarType(std::string_view s);

// Types a file can store, as read through loadScalar.
template <class T>
concept FileScalar = std::integral<T> || std::floating_point<T>;
static_assert(FileScalar<uint8_t> && FileScalar<int16_t> && FileScalar<float> && FileScalar<double>);

// One value of type T stored in the given byte order at p (any alignment).
template <FileScalar T>
T loadScalar(const void* p, bool bigEndian) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (bigEndian != (std::endian::native == std::endian::big))
        for (size_t i = 0; i < sizeof(T) / 2; ++i) {
            const unsigned char t = b[i];
            b[i] = b[sizeof(T) - 1 - i];
            b[sizeof(T) - 1 - i] = t;
        }
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}

// One value of type t at p, as a double (exact for every type but none of 64-bit width).
double decodeScalar(const void* p, ScalarType t, bool bigEndian);

}  // namespace rtfact::io
