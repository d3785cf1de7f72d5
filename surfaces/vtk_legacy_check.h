// Structural validation of legacy VTK (.vtk) POLYDATA files, done before any bytes reach
// VTK: vtkPolyDataReader trusts the counts of every section (a POLYGONS list shorter than
// declared, or cells whose point counts disagree with the declared size, crash VTK 9.1 in
// vtkDataReader::ReadString / vtkCellArray::ImportLegacyFormat). The file is walked section
// by section, ASCII or BINARY (big-endian), scanning the values without storing them.
#pragma once
#include <cstdint>
#include <string>

namespace rtfact::surfaces {

struct VtkLegacyHeader {
    bool vtk = false;          // the first line starts with "# vtk DataFile Version"
    int major = 0, minor = 0;  // file version (0.0 when unreadable, as VTK does)
    bool binary = false;
    std::string dataset;       // upper case type after DATASET ("POLYDATA"), empty if none
    std::string firstKeyword;  // the keyword after the format line (normally DATASET)
};

struct VtkLegacySummary {
    uint64_t points = 0;
    uint64_t cells = 0;  // vertices + lines + polygons + strips
};

// Reads the header (version line, title, ASCII|BINARY, DATASET type). Returns vtk=false
// when the first line is not a VTK legacy version line; throws Error(file, ...) when it
// is but the rest of the header is broken.
VtkLegacyHeader readVtkLegacyHeader(const std::string& file);

// Walks a POLYDATA file completely and throws Error(file, "<one-line problem>") on the
// first section whose declared data is missing, malformed or inconsistent (cell sizes,
// point indices, attribute counts, unknown sections, unsupported types).
VtkLegacySummary validateVtkLegacyPolyData(const std::string& file);

}  // namespace rtfact::surfaces
