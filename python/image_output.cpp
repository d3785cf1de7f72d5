#include "python/image_output.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/render/image_io.h"
#include "core/render/srgb.h"
#include "core/util/error.h"
#include "python/errors.h"

namespace py = pybind11;

namespace rtfact::python {

namespace {

// A float image as width, height and packed RGBA (alpha 1 for RGB input).
struct RGBA {
    int width = 0, height = 0;
    std::vector<float> rgba;
};

RGBA rgbaOf(py::handle obj) {
    const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(obj);
    if (!a) {
        PyErr_Clear();
        throwValue("image", "expected an (h, w, 4) or (h, w, 3) float array");
    }
    if (a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4) || a.shape(0) < 1 || a.shape(1) < 1)
        throwValue("image",
                   "expected an (h, w, 4) or (h, w, 3) float array, got " + std::to_string(a.ndim()) + " dimensions");
    RGBA r;
    r.height = int(a.shape(0));
    r.width = int(a.shape(1));
    const int c = int(a.shape(2));
    const size_t n = size_t(r.width) * size_t(r.height);
    r.rgba.resize(n * 4);
    const float* src = a.data();
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 4; ++k) r.rgba[i * 4 + size_t(k)] = k < c ? src[i * size_t(c) + size_t(k)] : 1.0f;
    return r;
}

}  // namespace

py::array_t<float> frameToNumpy(engine::Frame&& frame) {
    auto* pixels = new std::vector<float>(std::move(frame.rgba));
    py::capsule owner(pixels, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    const py::ssize_t w = frame.width, h = frame.height;
    return py::array_t<float>({h, w, py::ssize_t(4)}, {w * 16, py::ssize_t(16), py::ssize_t(4)}, pixels->data(), owner);
}

py::array_t<uint8_t> toSrgb8(py::handle image) {
    const RGBA img = rgbaOf(image);
    py::array_t<uint8_t> out({py::ssize_t(img.height), py::ssize_t(img.width), py::ssize_t(3)});
    uint8_t* dst = out.mutable_data();
    const size_t n = size_t(img.width) * size_t(img.height);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            // The curve and rounding of the CLI's 8-bit image writer.
            dst[i * 3 + size_t(c)] = linearToSrgb8(img.rgba[i * 4 + size_t(c)]);
        }
    return out;
}

void saveImage(const std::string& path, py::handle image) {
    const RGBA img = rgbaOf(image);
    py::gil_scoped_release noGil;
    writeImage(path, img.width, img.height, img.rgba);
}

py::array_t<float> readImage(const std::string& path) {
    Image img;
    {
        py::gil_scoped_release noGil;
        img = ::rtfact::readImage(path);
    }
    engine::Frame f;
    f.width = img.width;
    f.height = img.height;
    const size_t n = size_t(img.width) * size_t(img.height);
    f.rgba.assign(n * 4, 1.0f);
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < std::min(img.channels, 4); ++c)
            f.rgba[i * 4 + size_t(c)] = img.pixels[i * size_t(img.channels) + size_t(c)];
    if (img.channels < 3)  // grey: replicate into G and B
        for (size_t i = 0; i < n; ++i) f.rgba[i * 4 + 1] = f.rgba[i * 4 + 2] = f.rgba[i * 4];
    return frameToNumpy(std::move(f));
}

py::bytes pngBytes(py::handle image) {
    const RGBA img = rgbaOf(image);
    namespace fs = std::filesystem;
    // Through the core's writer (one PNG encoder in the tree), into a private temp file.
    std::string dir = (fs::temp_directory_path() / "rtfact-png-XXXXXX").string();
    if (!mkdtemp(dir.data())) throw Error(dir, "cannot create a temporary directory");
    const std::string path = dir + "/image.png";
    std::string bytes;
    try {
        py::gil_scoped_release noGil;
        writeImage(path, img.width, img.height, img.rgba);
        std::ifstream in(path, std::ios::binary);
        std::ostringstream ss;
        ss << in.rdbuf();
        bytes = ss.str();
    } catch (...) {
        std::error_code ec;
        fs::remove_all(dir, ec);
        throw;
    }
    std::error_code ec;
    fs::remove_all(dir, ec);
    return py::bytes(bytes);
}

}  // namespace rtfact::python
