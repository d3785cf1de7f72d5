// The options every rendering subcommand shares and their parsing.
#pragma once
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <utility>

#include "core/math/aabb.h"
#include "core/render/pinhole_camera.h"

namespace rtfact::app {

struct CommonOptions {
    std::string out;
    std::string size = "1024x1024";
    std::string eye, at, up;
    float fov = 45.0f;
    int threads = 0;
    int packet = 64;
    int spp = 1;
    bool quiet = false;
    bool stats = false;
    // Under mpirun: how the ranks share the work ("" or "image": image-parallel; docs/mpi.md).
    std::string distribute;

    // Filled by finalize().
    int width = 1024, height = 1024;
    std::optional<Vec3f> eyeV, atV, upV;

    // Adds the options to a subcommand; `defaultOut` is used when -o is not given.
    void addTo(CLI::App& cmd, const std::string& defaultOut);
    // Validates and converts the textual options; throws CLI::ValidationError.
    void finalize();
    // The camera: given --eye/--at/--up, or fitted to the scene bounds.
    CameraFrame frame(const AABB& bounds, Vec3f viewDir = {0.6f, 0.45f, 1.0f}, Vec3f up = {0, 1, 0}) const;
};

// Validators for floating-point options: CLI::Range and CLI::PositiveNumber let NaN
// through (every comparison with NaN is false) and print huge bounds in full.
// finiteRange: a finite number in [lo, hi]; positiveFinite: a finite number > 0;
// finiteNumber: any finite number. "Finite" as a float (the options are floats): values
// beyond the float range, or so small they would round to zero, are rejected too.
CLI::Validator finiteRange(double lo, double hi);
CLI::Validator positiveFinite();
CLI::Validator finiteNumber();

// Parses "x,y,z"; throws CLI::ValidationError naming the option.
Vec3f parseVec3(const std::string& text, const std::string& option);
// Parses "WxH".
std::pair<int, int> parseSize(const std::string& text);

}  // namespace rtfact::app
