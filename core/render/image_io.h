// Image files through OpenImageIO (loaded on first use: image_codec.h); the format follows
// the extension (PNG, EXR, TIFF, JPEG). Writes go to a temporary file in the same directory that is renamed into
// place, so a failed run never leaves a half-written image.
#pragma once
#include <string>
#include <vector>

namespace rtfact {

struct Image {
    int width = 0, height = 0, channels = 0;
    std::vector<float> pixels;  // linear values, channels interleaved
    float at(int x, int y, int c) const {
        return pixels[(size_t(y) * size_t(width) + size_t(x)) * size_t(channels) + size_t(c)];
    }
};

// Throws rtfact::Error when `path` has no supported extension or its directory is not
// writable; call before rendering so that bad output paths fail early.
void checkImageWritable(const std::string& path);

// `rgba`: width*height*4 linear floats whose colour already has the background composited.
// 8-bit formats (PNG, JPEG, TIFF) store sRGB-encoded RGB; EXR keeps linear RGBA floats.
void writeImage(const std::string& path, int width, int height, const std::vector<float>& rgba);

// Reads any OpenImageIO-supported file; 8-bit sRGB data is decoded to linear.
Image readImage(const std::string& path);

}  // namespace rtfact
