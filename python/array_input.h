// numpy arrays -> engine scenes. Arrays are checked here (dtype, shape, emptiness) and in
// the engine (finite values, sizes), every problem a ValueError naming the argument.
// Copies: volumes of uint8/uint16/int16/float32 are bricked straight from the array's
// memory in any layout (no dense copy); other volume dtypes are converted to float32
// first (one copy). Points and meshes are copied once into the engine's cloud/mesh (it
// keeps them to rebuild for other settings): float32 C-contiguous N x 3 is one memcpy.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <string>

#include "engine/scene.h"

namespace rtfact::python {

// xyz: N x 3 float32/float64; colors: N x 3 uint8 (0..255) or float (0..1); normals:
// N x 3 float; radius: a number (every point) or N floats; intensity: N floats. None: absent.
engine::Scene pointsFromNumpy(pybind11::handle xyz, pybind11::handle colors, pybind11::handle normals,
                              pybind11::handle radius, pybind11::handle intensity);

// vertices: V x 3 float32/float64; faces: F x 3 integer indices into vertices.
engine::Scene meshFromNumpy(pybind11::handle vertices, pybind11::handle faces);

// A 3D array indexed [z, y, x] (order "zyx", numpy's C order of an image stack) or
// [x, y, z] (order "xyz", Fortran order as written by many simulation codes); any strides.
engine::Scene volumeFromNumpy(pybind11::handle array, std::array<float, 3> spacing, std::array<float, 3> origin,
                              const std::string& order);

}  // namespace rtfact::python
