// The Modality attribute (0008,0060: "CT", "MR", "PT", ...) of a DICOM part-10 file, which
// VTK's DICOM reader does not expose. Own element walker over the file meta group and the
// start of the data set (explicit or implicit VR, little endian); it never reads past the
// first 64 KiB and stops at the first element beyond (0008,0060).
#pragma once
#include <string>

namespace rtfact::volume {

// The modality in upper case, or "" when the file has none or is not parsable that far.
std::string readDicomModality(const std::string& path);
// The same from the file's first bytes (for tests).
std::string parseDicomModality(const std::string& bytes);

}  // namespace rtfact::volume
