#include "core/render/image_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>

#include "core/io/file_helpers.h"
#include "core/render/image_codec.h"
#include "core/render/srgb.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/memory_budget.h"

namespace rtfact {

namespace fs = std::filesystem;

namespace {

using io::lowerExt;

// libpng and libjpeg print their own diagnostics on stderr before the codec reports the
// failure; while an input image is decoded stderr goes to /dev/null, so that the user
// sees our one-line error only. (Images are read before rendering starts: no other
// thread is writing to stderr then.)
class SilenceStderr {
   public:
    SilenceStderr() {
        std::fflush(stderr);
        saved_ = ::dup(2);
        const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
        if (saved_ >= 0 && null >= 0) ::dup2(null, 2);
        if (null >= 0) ::close(null);
    }
    ~SilenceStderr() {
        std::fflush(stderr);
        if (saved_ >= 0) {
            ::dup2(saved_, 2);
            ::close(saved_);
        }
    }
    SilenceStderr(const SilenceStderr&) = delete;
    SilenceStderr& operator=(const SilenceStderr&) = delete;

   private:
    int saved_ = -1;
};

// Library messages can span lines; ours are one line.
std::string oneLine(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    std::replace(s.begin(), s.end(), '\n', ' ');
    return s.empty() ? "unknown error" : s;
}

bool isFloatFormat(const std::string& ext) { return ext == ".exr" || ext == ".hdr"; }

std::string tempPathFor(const std::string& path) {
    const fs::path p(path);
    std::random_device rd;
    char tag[32];
    std::snprintf(tag, sizeof tag, ".tmp%08x", rd());
    return (p.parent_path() / ("." + p.stem().string() + tag + p.extension().string())).string();
}

}  // namespace

void checkImageWritable(const std::string& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw Error(path, "output path is a directory");
    const std::string ext = lowerExt(path);
    if (ext != ".png" && ext != ".exr" && ext != ".tif" && ext != ".tiff" && ext != ".jpg" && ext != ".jpeg" &&
        ext != ".hdr")
        throw Error(path, "unsupported image format '" + ext + "' (use .png, .exr, .tif, .jpg)");
    fs::path dir = fs::path(path).parent_path();
    if (dir.empty()) dir = ".";
    if (!fs::is_directory(dir, ec)) throw Error(path, "output directory does not exist");
    if (access(dir.c_str(), W_OK) != 0) throw Error(path, "output directory is not writable");
}

void writeImage(const std::string& path, int width, int height, const std::vector<float>& rgba) {
    checkImageWritable(path);
    const std::string ext = lowerExt(path);
    const std::string tmp = tempPathFor(path);
    const bool floats = isFloatFormat(ext);
    const int channels = floats ? 4 : 3;  // 8-bit images carry the background-composited colour
    const ImageCodec& codec = imageCodec(path);
    std::vector<unsigned char> px;
    if (!floats) {
        px.resize(size_t(width) * size_t(height) * size_t(channels));
        for (size_t i = 0, n = size_t(width) * size_t(height); i < n; ++i) {
            for (int c = 0; c < channels; ++c)
                px[i * size_t(channels) + size_t(c)] = linearToSrgb8(rgba[i * 4 + size_t(c)]);
        }
    }
    std::string err;
    if (!codec.write(tmp, width, height, channels, floats, floats ? static_cast<const void*>(rgba.data()) : px.data(),
                     err)) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw Error(path, "cannot write image: " + oneLine(err));
    }
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw Error(path, "cannot move the finished image into place");
    }
}

Image readImage(const std::string& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw Error(path, "is a directory, not an image");
    requireRegularFile(path);  // a named pipe would block the image reader
    const uint64_t fileBytes = fs::file_size(path, ec);
    if (ec || fileBytes == 0) throw Error(path, "empty image file");
    const ImageCodec& codec = imageCodec(path);
    SilenceStderr quiet;
    ImageHeader spec;
    std::string err;
    std::unique_ptr<void, void (*)(void*)> in(codec.open(path, spec, err), codec.close);
    if (!in) throw Error(path, "cannot read image: " + oneLine(err));
    if (spec.width <= 0 || spec.height <= 0 || spec.channels <= 0 || spec.channels > 64 || spec.depth > 1)
        throw Error(path, "unsupported image size " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                              "x" + std::to_string(spec.depth) + " with " + std::to_string(spec.channels) +
                              " channels");
    // A lying header must not make us allocate: no format we read compresses better than
    // deflate's 1032:1, so 4096 decoded bytes per file byte is a generous bound.
    const uint64_t decoded = uint64_t(spec.width) * uint64_t(spec.height) * uint64_t(spec.channels);
    if (decoded * spec.formatBytes / 4096 > fileBytes)
        throw Error(path, "image header claims " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                              " pixels, more than a file of " + std::to_string(fileBytes) + " bytes can hold");
    checkMemory(path, decoded * sizeof(float),
                "a " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " image",
                "use a smaller texture");
    Image img;
    img.width = spec.width;
    img.height = spec.height;
    img.channels = spec.channels;
    img.pixels.resize(size_t(decoded));
    if (!codec.read(in.get(), img.channels, img.pixels.data(), err))
        throw Error(path, "cannot decode image: " + oneLine(err));
    for (float v : img.pixels)
        if (!std::isfinite(v)) throw Error(path, "image holds NaN or infinite values");
    if (spec.uint8) {
        for (size_t i = 0; i < img.pixels.size(); ++i)
            if (img.channels < 4 || i % size_t(img.channels) != 3) img.pixels[i] = srgbToLinear(img.pixels[i]);
    }
    return img;
}

}  // namespace rtfact
