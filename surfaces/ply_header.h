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
    int typeBytes = 4;       // scalar type (or list item type) size in bytes
    int countBytes = 0;      // list count type size
    char typeKind = 'f';     // 'i' signed, 'u' unsigned, 'f' floating point
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

// Reads and checks the header of a PLY file: syntax, known types, and that the file is
// large enough for the element counts it announces. Throws Error(file, ...).
PlyHeader readPlyHeader(const std::string& file);
// True when the file starts with the "ply" magic line.
bool isPlyFile(const std::string& file);

}  // namespace rtfact
