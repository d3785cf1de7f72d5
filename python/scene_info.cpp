#include "python/scene_info.h"

#include <cstdlib>
#include <sstream>

namespace py = pybind11;

namespace rtfact::python {

namespace {

// The value as a number (int when it is written as one), or None.
py::object numberOf(const std::string& t) {
    if (t.empty()) return py::none();
    char* end = nullptr;
    const long long i = std::strtoll(t.c_str(), &end, 10);
    if (*end == 0) return py::int_(i);
    const double d = std::strtod(t.c_str(), &end);
    if (*end == 0) return py::float_(d);
    return py::none();
}

py::object valueOf(const std::string& v) {
    std::string s = v;
    const bool bracketed = s.find('[') != std::string::npos;
    for (char& c : s)
        if (c == '[' || c == ']') c = ' ';
    std::istringstream in(s);
    std::vector<py::object> nums;
    for (std::string tok; in >> tok;) {
        if (tok == "-" || tok == "x" || tok == "..") continue;
        py::object n = numberOf(tok);
        if (n.is_none()) return py::str(v);
        nums.push_back(n);
    }
    if (nums.empty()) return py::str(v);
    if (nums.size() == 1) return nums[0];
    if (bracketed && nums.size() == 6)
        return py::make_tuple(py::make_tuple(nums[0], nums[1], nums[2]), py::make_tuple(nums[3], nums[4], nums[5]));
    py::tuple t(nums.size());
    for (size_t i = 0; i < nums.size(); ++i) t[i] = nums[i];
    return t;
}

}  // namespace

py::dict infoDict(const std::vector<std::pair<std::string, std::string>>& entries) {
    py::dict d;
    for (const auto& [k, v] : entries) d[py::str(k)] = valueOf(v);
    return d;
}

}  // namespace rtfact::python
