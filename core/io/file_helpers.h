// Small file-name and file-size helpers shared by every reader.
#pragma once
#include <cstdint>
#include <string>

namespace rtfact::io {

// ASCII lower case (locale-independent; bytes >= 0x80 are kept).
std::string lower(std::string s);
// The extension with its dot, lower case: "scan.PLY" -> ".ply"; empty without one.
std::string lowerExt(const std::string& path);
// True when `s` ends with `suffix` (case-sensitive).
bool endsWith(const std::string& s, const std::string& suffix);
// The size of a regular file; throws Error(path, ...) for anything else (a named pipe
// would block a reader) or when the size cannot be read.
uint64_t fileSize(const std::string& path);

}  // namespace rtfact::io
