#include "python/errors.h"

#include "engine/usage_error.h"

namespace py = pybind11;

namespace rtfact::python {

void registerErrors(py::module_& m) {
    // Lives as long as the module (pybind11's documented pattern for custom exceptions).
    static py::exception<Error> error(m, "Error", PyExc_OSError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const engine::UsageError& e) {
            PyErr_SetString(PyExc_ValueError, e.message().c_str());
        } catch (const Error& e) {
            PyErr_SetString(error.ptr(), e.message().c_str());
        }
    });
}

void throwValue(const std::string& what, const std::string& problem) { throw py::value_error(what + ": " + problem); }

}  // namespace rtfact::python
