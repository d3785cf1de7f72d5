#include "core/io/file_helpers.h"

#include <filesystem>

#include "core/util/error.h"
#include "core/util/input_file.h"

namespace rtfact::io {

std::string lower(std::string s) {
    for (char& c : s)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return s;
}

std::string lowerExt(const std::string& path) { return lower(std::filesystem::path(path).extension().string()); }

bool endsWith(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

uint64_t fileSize(const std::string& path) {
    requireRegularFile(path);
    std::error_code ec;
    const uint64_t s = std::filesystem::file_size(path, ec);
    if (ec) throw Error(path, "cannot read file size (" + ec.message() + ")");
    return s;
}

}  // namespace rtfact::io
