// Structural check of an OpenVDB file (io::File layout, file format versions 222-224) before
// OpenVDB opens it: OpenVDB trusts the lengths and counts it reads (strings, metadata, node
// counts, compressed chunk sizes) and, on a truncated or corrupted file, reads past the end,
// allocates by garbage lengths or loops for minutes. Our own reader walks the header, the
// file metadata, the grid descriptors, each grid's metadata and transform and, for float and
// double trees, the whole topology and the buffer section, with every length bounded by the
// bytes left in its region, and no allocation proportional to a declared length.
// No OpenVDB headers here.
#pragma once
#include <string>

namespace rtfact::volume {

// Throws rtfact::Error(path, "<one-line problem>") when the file is not a well-formed VDB
// file (or uses a layout this check does not know: no grid offsets, file version < 222).
void checkVdbFile(const std::string& path);

}  // namespace rtfact::volume
