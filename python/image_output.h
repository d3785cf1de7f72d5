// Rendered frames as numpy images and images to files: a frame's RGBA floats become an
// (h, w, 4) float32 array without a copy (the array owns the frame's buffer); 8-bit sRGB
// conversion and file writing use the core's image I/O, so a saved PNG is what
// `rtfact ... -o x.png` writes for the same pixels.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

#include "engine/render_session.h"

namespace rtfact::python {

// (h, w, 4) float32 linear RGBA owning the frame's pixels.
pybind11::array_t<float> frameToNumpy(engine::Frame&& frame);

// (h, w, 3) uint8 sRGB of an (h, w, 3|4) float image (alpha dropped: the colour is
// already composited on the background), rounded as the PNG writer rounds.
pybind11::array_t<uint8_t> toSrgb8(pybind11::handle image);

// Writes an (h, w, 3|4) float image (linear) to PNG/EXR/TIFF/JPEG by extension.
void saveImage(const std::string& path, pybind11::handle image);

// Reads an image file as (h, w, 4) float32 linear RGBA (8-bit sRGB decoded to linear).
pybind11::array_t<float> readImage(const std::string& path);

// The PNG file bytes of an image (Jupyter's _repr_png_).
pybind11::bytes pngBytes(pybind11::handle image);

}  // namespace rtfact::python
