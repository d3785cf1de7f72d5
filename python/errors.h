// Engine exceptions as Python exceptions carrying the CLI's one-line message
// ("<source>: <what is wrong>"): engine::UsageError (a bad setting or array) becomes
// ValueError, rtfact::Error (a file or the data in it) becomes rtfact.Error, a subclass
// of OSError.
#pragma once
#include <pybind11/pybind11.h>

#include <string>

namespace rtfact::python {

void registerErrors(pybind11::module_& m);

// ValueError("<what>: <problem>") for bad arrays and settings found by the module itself.
[[noreturn]] void throwValue(const std::string& what, const std::string& problem);

}  // namespace rtfact::python
