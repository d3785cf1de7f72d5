// Mesh files: PLY (ASCII/binary), OBJ (+MTL, textures), STL, VTK legacy and VTP. VTK's
// readers are used for STL/VTK/VTP behind this header (after our own size checks); PLY
// and OBJ/MTL are parsed by us: vtkPLYReader crashes on corrupted face lists and VTK
// 9.1's OBJ reader drops usemtl material assignments.
#pragma once
#include <string>
#include <vector>

#include "surfaces/mesh.h"

namespace rtfact::surfaces {

// What kind of mesh file a path holds, judged from its extension and header, without
// loading it. NotMesh covers point clouds (PLY without faces) and volume datasets.
enum class MeshFileKind { NotMesh, Ply, Obj, Stl, VtkLegacy, Vtp };
MeshFileKind meshFileKind(const std::string& file);

// Loads one mesh file: triangulates polygons, computes normals when absent, validates.
// Throws Error(file, "what is wrong") for unreadable, malformed or empty files.
Mesh loadMesh(const std::string& file);
// Several files merged into one mesh (materials kept per file).
Mesh loadMeshes(const std::vector<std::string>& files);

}  // namespace rtfact::surfaces
