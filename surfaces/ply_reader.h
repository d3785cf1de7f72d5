// Triangle meshes from PLY files (ASCII, binary little/big endian): polygons ("face",
// fanned) and triangle strips ("tristrips", -1 restarts a strip). The header is read by
// core/io/ply_header.h; every count and index of the body is checked against the bytes
// actually present (vtkPLYReader crashes on corrupted face lists).
#pragma once
#include <cstdint>
#include <string>

#include "core/io/mapped_file.h"
#include "core/io/ply_header.h"
#include "surfaces/mesh.h"

namespace rtfact::surfaces {

// Reads the body of `f`, whose header is `h` (from io::readPlyHeader(f)).
Mesh readPly(const io::MappedFile& f, const io::PlyHeader& h);

// Elements holding triangles: "face" (polygons, fanned) and "tristrips" (triangle
// strips, -1 restarts a strip).
bool isPlyFaceElement(const std::string& element);
// The list property with a face's or strip's vertex indices ("vertex_indices" or
// "vertex_index"); null when the element has none.
const io::PlyProperty* plyIndexList(const io::PlyElement& e);
// True when some face or strip element has an index list and at least one entry.
bool plyHasFaces(const io::PlyHeader& h);
// The triangles to expect, for the memory check before reading: one per polygon (a
// polygon fans to more, but counts are what the other formats check too) and, for
// strips, one per index that the bytes left after the other elements can hold (binary:
// an upper bound; ASCII: an estimate from the typical index width). The check after
// reading uses the real count.
uint64_t plyTriangleEstimate(const io::PlyHeader& h);

}  // namespace rtfact::surfaces
