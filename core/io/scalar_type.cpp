#include "core/io/scalar_type.h"

namespace rtfact::io {

const char* scalarTypeName(ScalarType t) {
    switch (t) {
        case ScalarType::I8:
            return "i8";
        case ScalarType::U8:
            return "u8";
        case ScalarType::I16:
            return "i16";
        case ScalarType::U16:
            return "u16";
        case ScalarType::I32:
            return "i32";
        case ScalarType::U32:
            return "u32";
        case ScalarType::F32:
            return "f32";
        case ScalarType::F64:
            return "f64";
    }
    return "?";
}

std::optional<ScalarType> parsePlyScalarType(std::string_view s) {
    if (s == "char" || s == "int8") return ScalarType::I8;
    if (s == "uchar" || s == "uint8") return ScalarType::U8;
    if (s == "short" || s == "int16") return ScalarType::I16;
    if (s == "ushort" || s == "uint16") return ScalarType::U16;
    if (s == "int" || s == "int32") return ScalarType::I32;
    if (s == "uint" || s == "uint32") return ScalarType::U32;
    if (s == "float" || s == "float32") return ScalarType::F32;
    if (s == "double" || s == "float64") return ScalarType::F64;
    return std::nullopt;
}

double decodeScalar(const void* p, ScalarType t, bool bigEndian) {
    switch (t) {
        case ScalarType::I8:
            return loadScalar<int8_t>(p, bigEndian);
        case ScalarType::U8:
            return loadScalar<uint8_t>(p, bigEndian);
        case ScalarType::I16:
            return loadScalar<int16_t>(p, bigEndian);
        case ScalarType::U16:
            return loadScalar<uint16_t>(p, bigEndian);
        case ScalarType::I32:
            return loadScalar<int32_t>(p, bigEndian);
        case ScalarType::U32:
            return loadScalar<uint32_t>(p, bigEndian);
        case ScalarType::F32:
            return loadScalar<float>(p, bigEndian);
        case ScalarType::F64:
            return loadScalar<double>(p, bigEndian);
    }
    return 0;
}

}  // namespace rtfact::io
