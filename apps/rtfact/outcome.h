// How rtfact ends: a step's outcome (0, or the exit status and its one-line message), from
// the exception it threw: usage errors 2, everything else 1. main() and the MPI drivers
// (which first agree across ranks on the failure) share it.
#pragma once
#include <CLI/CLI.hpp>
#include <exception>
#include <new>
#include <string>

#include "core/util/error.h"
#include "engine/usage_error.h"

namespace rtfact::app {

struct Outcome {
    int status = 0;
    std::string message;
};

// The outcome of the exception being handled (call inside a catch block).
inline Outcome currentOutcome() {
    try {
        throw;
    } catch (const CLI::ParseError& e) {
        return {2, e.what()};
    } catch (const engine::UsageError& e) {
        return {2, e.message()};
    } catch (const Error& e) {
        return {1, e.message()};
    } catch (const std::bad_alloc&) {
        return {1, "out of memory"};
    } catch (const std::exception& e) {
        return {1, e.what()};
    } catch (...) {
        return {1, "unknown error"};
    }
}

// Runs `f`, turning its exceptions into the outcome main() would give them.
template <class F>
Outcome attempt(F&& f) {
    try {
        f();
    } catch (...) {
        return currentOutcome();
    }
    return {};
}

}  // namespace rtfact::app
