// Checks an input path before any reader opens it: a named pipe, a device or a socket
// would block a reader (or stream forever), so only regular files (or directories where
// one is expected) are accepted. Errors are rtfact::Error naming the path.
#pragma once
#include <string>

namespace rtfact {

// Throws unless `path` names a regular file (symlinks are followed).
void requireRegularFile(const std::string& path);
// Throws unless `path` names a directory.
void requireDirectory(const std::string& path);
// Throws unless `path` names a regular file or a directory; true for a directory.
bool requireFileOrDirectory(const std::string& path);

}  // namespace rtfact
