#include "apps/view/image_encoders.h"

#include <turbojpeg.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include "core/render/image_io.h"
#include "core/render/srgb.h"
#include "core/util/error.h"

namespace rtfact::viewer {

namespace {

// Linear -> sRGB byte through a table over [0, 1] (4096 steps: within one byte step of
// the exact curve; frames are converted at frame rate).
const std::array<uint8_t, 4097>& srgbTable() {
    static const std::array<uint8_t, 4097> table = [] {
        std::array<uint8_t, 4097> t{};
        for (size_t i = 0; i < t.size(); ++i) {
            const float v = float(i) / 4096.0f;
            t[i] = linearToSrgb8(v);
        }
        return t;
    }();
    return table;
}

}  // namespace

std::vector<uint8_t> toSrgb8(const engine::Frame& frame) {
    const auto& t = srgbTable();
    const size_t n = size_t(frame.width) * size_t(frame.height);
    std::vector<uint8_t> rgb(n * 3);
    for (size_t p = 0; p < n; ++p)
        for (size_t c = 0; c < 3; ++c) {
            const float v = frame.rgba[p * 4 + c];
            // NaN goes to 0 like the image writer's clamp.
            const float u = v > 0.0f ? std::min(v, 1.0f) : 0.0f;
            rgb[p * 3 + c] = t[size_t(u * 4096.0f + 0.5f)];
        }
    return rgb;
}

std::vector<uint8_t> encodeJpeg(const engine::Frame& frame, int quality) {
    const std::vector<uint8_t> rgb = toSrgb8(frame);
    tjhandle h = tjInitCompress();
    if (!h) throw Error("jpeg", "cannot initialise libjpeg-turbo");
    unsigned char* out = nullptr;
    unsigned long size = 0;
    const int rc = tjCompress2(h, rgb.data(), frame.width, 0, frame.height, TJPF_RGB, &out, &size, TJSAMP_420,
                               std::clamp(quality, 1, 100), TJFLAG_FASTDCT);
    std::vector<uint8_t> bytes;
    std::string err;
    if (rc == 0)
        bytes.assign(out, out + size);
    else
        err = tjGetErrorStr2(h);
    tjFree(out);
    tjDestroy(h);
    if (rc != 0) throw Error("jpeg", err);
    return bytes;
}

std::vector<uint8_t> encodePng(const engine::Frame& frame) {
    namespace fs = std::filesystem;
    std::random_device rd;
    const fs::path path = fs::temp_directory_path() / ("rtfact-view-" + std::to_string(rd()) + ".png");
    writeImage(path.string(), frame.width, frame.height, frame.rgba);
    std::ifstream in(path, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    std::error_code ec;
    fs::remove(path, ec);
    if (bytes.empty()) throw Error(path.string(), "PNG encoding produced no data");
    return bytes;
}

}  // namespace rtfact::viewer
