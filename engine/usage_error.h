// A request the caller got wrong (an unknown integrator name, a setting out of range),
// as opposed to bad input data: the CLI exits 2 for it, like for its own option errors.
#pragma once
#include "core/util/error.h"

namespace rtfact::engine {

class UsageError : public Error {
   public:
    // `option`: the setting or option concerned, e.g. "--integrator".
    UsageError(std::string option, const std::string& what) : Error(std::move(option), what) {}
};

}  // namespace rtfact::engine
