// The PLY header: format, elements and their (list) properties. One reader for point
// clouds and meshes, with one set of limits: the header must end within its first
// 1 MiB, and the element counts must fit in the bytes that follow it, so that no body
// reader can be driven into a long loop or a large allocation by a lying header.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/io/scalar_type.h"

namespace rtfact::io {

class MappedFile;

struct PlyProperty {
    std::string name;
    ScalarType type = ScalarType::F32;  // the scalar, or a list's item type
    bool isList = false;
    ScalarType countType = ScalarType::U8;  // a list's length type
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> props;
    // Bytes one binary entry occupies when it has no list property, else 0.
    size_t fixedBytes() const;
};

enum class PlyFormat { Ascii, BinaryLE, BinaryBE };

struct PlyHeader {
    PlyFormat format = PlyFormat::Ascii;
    std::vector<PlyElement> elements;
    uint64_t headerBytes = 0;  // offset of the first body byte
    uint64_t fileBytes = 0;

    const PlyElement* find(const std::string& name) const;
    uint64_t count(const std::string& name) const {
        const PlyElement* e = find(name);
        return e ? e->count : 0;
    }
    bool hasProperty(const std::string& element, const std::string& prop) const;
    bool ascii() const { return format == PlyFormat::Ascii; }
    bool bigEndian() const { return format == PlyFormat::BinaryBE; }
    // "ply ascii", "ply binary_little_endian", "ply binary_big_endian".
    std::string formatName() const;
};

// Headers are a few dozen short lines; the limit stops a file without end_header (or
// with a giant comment) from being parsed whole.
inline constexpr uint64_t kMaxPlyHeaderBytes = uint64_t(1) << 20;

// Parses the header at the start of `head` (the first min(fileBytes, kMaxPlyHeaderBytes)
// bytes of a file of fileBytes bytes): syntax, known types, counts, and that the file is
// large enough for the elements it announces (binary: scalar sizes and list lengths;
// ASCII: a digit and a separator per value). Throws Error(file, ...).
PlyHeader parsePlyHeader(std::string_view head, uint64_t fileBytes, const std::string& file);
PlyHeader readPlyHeader(const MappedFile& f);

// True when the file starts with the "ply" magic line (reads 4 bytes; false when the
// file cannot be read).
bool isPlyFile(const std::string& file);

}  // namespace rtfact::io
