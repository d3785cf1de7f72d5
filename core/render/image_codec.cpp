#include "core/render/image_codec.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>
#include <vector>

#include "core/util/error.h"

#ifndef RTFACT_IMAGE_CODEC_BUILD_DIR
#define RTFACT_IMAGE_CODEC_BUILD_DIR ""
#endif

namespace rtfact {

namespace {

constexpr const char* kModule = "rtfact_image_oiio.so";

// Next to the binary or module this code is linked into (the rtfact executable, the Python
// extension, a test), then where the build put it.
std::vector<std::filesystem::path> candidates() {
    std::vector<std::filesystem::path> dirs;
    Dl_info info{};
    if (dladdr(reinterpret_cast<const void*>(&candidates), &info) && info.dli_fname && *info.dli_fname) {
        std::error_code ec;
        const auto self = std::filesystem::canonical(info.dli_fname, ec);
        if (!ec) dirs.push_back(self.parent_path() / kModule);
    }
    if (*RTFACT_IMAGE_CODEC_BUILD_DIR) dirs.push_back(std::filesystem::path(RTFACT_IMAGE_CODEC_BUILD_DIR) / kModule);
    return dirs;
}

struct Loaded {
    const ImageCodec* codec = nullptr;
    std::string error;
};

Loaded load() {
    Loaded r;
    std::string tried;
    for (const auto& p : candidates()) {
        std::error_code ec;
        if (!std::filesystem::exists(p, ec)) {
            tried += (tried.empty() ? "" : ", ") + p.string();
            continue;
        }
        void* h = dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!h) {
            const char* e = dlerror();
            r.error = "cannot load the image module " + p.string() + ": " + (e ? e : "unknown error");
            return r;
        }
        using Entry = const ImageCodec* (*)();
        auto entry = reinterpret_cast<Entry>(dlsym(h, "rtfact_image_codec"));
        const ImageCodec* c = entry ? entry() : nullptr;
        if (!c || c->version != kImageCodecVersion) {
            r.error = "the image module " + p.string() + " is from another RTfact build";
            return r;
        }
        r.codec = c;
        return r;
    }
    r.error = std::string("image support is missing: ") + kModule + " was not found (looked for " + tried + ")";
    return r;
}

}  // namespace

const ImageCodec& imageCodec(const std::string& source) {
    static const Loaded loaded = load();  // dlopen once; a missing module stays missing
    if (!loaded.codec) throw Error(source, loaded.error);
    return *loaded.codec;
}

}  // namespace rtfact
