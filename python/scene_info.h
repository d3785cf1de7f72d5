// What a scene or a file holds (engine::Scene::info(), engine::fileInfo()) as a Python
// dict: numbers become int/float, "lo .. hi" ranges, "X x Y x Z" dims and spacings
// tuples, bounds ((x, y, z), (x, y, z)); everything else stays text.
#pragma once
#include <pybind11/pybind11.h>

#include <string>
#include <utility>
#include <vector>

namespace rtfact::python {

pybind11::dict infoDict(const std::vector<std::pair<std::string, std::string>>& entries);

}  // namespace rtfact::python
