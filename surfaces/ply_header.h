// PLY header parsing and size validation, done before any bytes reach VTK: VTK's PLY
// reader trusts the element counts of the header and allocates (or reads) blindly.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace rtfact {

struct PlyProperty {
    std::string name;
    bool isList = false;
    int typeBytes = 4;    // scalar type (or list item type) size in bytes
    int countBytes = 0;   // list count type size
    char typeKind = 'f';  // 'i' signed, 'u' unsigned, 'f' floating point
    char countKind = 'u';
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> props;
};

struct PlyHeader {
    enum class Format { Ascii, BinaryLE, BinaryBE } format = Format::Ascii;
    std::vector<PlyElement> elements;
    uint64_t headerBytes = 0;  // offset of the first data byte
    uint64_t fileBytes = 0;

    const PlyElement* find(const std::string& name) const;
    uint64_t count(const std::string& name) const {
        const PlyElement* e = find(name);
        return e ? e->count : 0;
    }
    bool hasProperty(const std::string& element, const std::string& prop) const;
};

// Headers are a few dozen short lines; the limit stops a file without end_header (or
// with a giant comment) from being read into memory as one header line.
inline constexpr uint64_t kMaxPlyHeaderBytes = 1 << 20;

// Reads and checks the header of a PLY file: syntax, known types, and that the file is
// large enough for the element counts it announces. Throws Error(file, ...).
PlyHeader readPlyHeader(const std::string& file);

// Elements holding triangles: "face" (polygons, fanned) and "tristrips" (triangle
// strips, -1 restarts a strip).
bool isPlyFaceElement(const std::string& element);
// The list property with a face's or strip's vertex indices ("vertex_indices" or
// "vertex_index"); null when the element has none.
const PlyProperty* plyIndexList(const PlyElement& e);
// True when some face or strip element has an index list and at least one entry.
bool plyHasFaces(const PlyHeader& h);
// The triangles to expect, for the memory check before reading: one per polygon (a
// polygon fans to more, but counts are what the other formats check too) and, for
// strips, one per index that the bytes left after the other elements can hold (binary:
// an upper bound; ASCII: an estimate from the typical index width). The check after
// reading uses the real count.
uint64_t plyTriangleEstimate(const PlyHeader& h);
// True when the file starts with the "ply" magic line.
bool isPlyFile(const std::string& file);

}  // namespace rtfact
