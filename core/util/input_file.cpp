#include "core/util/input_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

#include "core/util/error.h"

namespace rtfact {

namespace {
// stat() follows symlinks and never opens the file, so it cannot block on a FIFO.
struct stat statOrThrow(const std::string& path) {
    struct stat st {};
    if (path.empty()) throw Error("", "empty file name");
    if (::stat(path.c_str(), &st) != 0) {
        if (errno == ENOENT || errno == ENOTDIR) throw Error(path, "no such file or directory");
        throw Error(path, std::string("cannot access: ") + std::strerror(errno));
    }
    return st;
}
const char* kindOf(mode_t m) {
    if (S_ISFIFO(m)) return "is a named pipe, not a regular file";
    if (S_ISCHR(m) || S_ISBLK(m)) return "is a device, not a regular file";
    if (S_ISSOCK(m)) return "is a socket, not a regular file";
    return "is not a regular file";
}
}  // namespace

void requireRegularFile(const std::string& path) {
    const struct stat st = statOrThrow(path);
    if (S_ISDIR(st.st_mode)) throw Error(path, "is a directory, not a file");
    if (!S_ISREG(st.st_mode)) throw Error(path, kindOf(st.st_mode));
}

void requireDirectory(const std::string& path) {
    const struct stat st = statOrThrow(path);
    if (!S_ISDIR(st.st_mode)) throw Error(path, "is not a directory");
}

bool requireFileOrDirectory(const std::string& path) {
    const struct stat st = statOrThrow(path);
    if (S_ISDIR(st.st_mode)) return true;
    if (!S_ISREG(st.st_mode)) throw Error(path, kindOf(st.st_mode));
    return false;
}

}  // namespace rtfact
