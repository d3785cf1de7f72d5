// The module rtfact_image_oiio.so: the ImageCodec table over OpenImageIO (see
// image_codec.h for why it is a module loaded on first use).
#include <OpenImageIO/imageio.h>

#include <memory>

#include "core/render/image_codec.h"

namespace {

using rtfact::ImageHeader;

bool writeOiio(const std::string& path, int width, int height, int channels, bool floats, const void* pixels,
               std::string& error) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
        error = OIIO::geterror();
        return false;
    }
    OIIO::ImageSpec spec(width, height, channels, floats ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    if (!floats) spec.attribute("oiio:ColorSpace", "sRGB");
    bool ok = out->open(path, spec);
    if (ok) {
        ok = out->write_image(floats ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8, pixels);
        ok = out->close() && ok;
    }
    if (!ok) error = out->geterror();
    return ok;
}

void* openOiio(const std::string& path, ImageHeader& header, std::string& error) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        error = OIIO::geterror();
        return nullptr;
    }
    const OIIO::ImageSpec& spec = in->spec();
    header.width = spec.width;
    header.height = spec.height;
    header.depth = spec.depth;
    header.channels = spec.nchannels;
    header.formatBytes = spec.format.size();
    header.uint8 = spec.format == OIIO::TypeDesc::UINT8;
    return in.release();
}

bool readOiio(void* reader, int channels, float* out, std::string& error) {
    auto* in = static_cast<OIIO::ImageInput*>(reader);
    if (in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, out)) return true;
    error = in->geterror();
    return false;
}

void closeOiio(void* reader) { delete static_cast<OIIO::ImageInput*>(reader); }

constexpr rtfact::ImageCodec kCodec{rtfact::kImageCodecVersion, writeOiio, openOiio, readOiio, closeOiio};

}  // namespace

extern "C" __attribute__((visibility("default"))) const rtfact::ImageCodec* rtfact_image_codec() { return &kCodec; }
