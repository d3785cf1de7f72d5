// The image codec behind readImage/writeImage: OpenImageIO, loaded on first use from the
// module rtfact_image_oiio.so. Debian's OpenImageIO links every format plugin (ffmpeg,
// OpenCV, DCMTK, ...: 260 shared libraries, about 0.6 s of dynamic linking), so linking it
// into every binary made each start of `rtfact`, of an MPI rank and of `import rtfact` pay
// that, even for --help or a usage error. Only a run that reads or writes an image now does.
#pragma once
#include <cstddef>
#include <string>

namespace rtfact {

struct ImageHeader {
    int width = 0, height = 0, depth = 0, channels = 0;
    size_t formatBytes = 0;  // bytes per channel value in the file
    bool uint8 = false;      // 8-bit data (sRGB-encoded by convention)
};

// The module's table; the module and its users come from one build (same compiler and
// standard library), so C++ types may cross. Errors come back as the library's message.
struct ImageCodec {
    int version;
    // Writes width*height*channels values (float when `floats`, else uint8) to `path`.
    bool (*write)(const std::string& path, int width, int height, int channels, bool floats, const void* pixels,
                  std::string& error);
    // Opens `path` and fills its header; null on failure.
    void* (*open)(const std::string& path, ImageHeader& header, std::string& error);
    // Decodes the first image of an opened file to `channels` floats per pixel.
    bool (*read)(void* reader, int channels, float* out, std::string& error);
    void (*close)(void* reader);
};

inline constexpr int kImageCodecVersion = 1;

// The loaded codec (loaded once, thread-safe); throws rtfact::Error naming `source` when
// the module cannot be found or loaded.
const ImageCodec& imageCodec(const std::string& source);

}  // namespace rtfact
