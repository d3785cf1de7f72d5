// The options every rendering subcommand shares, their parsing and the --stats output.
#pragma once
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

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

// key=value lines printed at the end of a run with --stats.
class Stats {
   public:
    void add(const std::string& key, const std::string& value) { kv_.emplace_back(key, value); }
    void add(const std::string& key, double value);
    void add(const std::string& key, long long value) { add(key, std::to_string(value)); }
    void add(const std::string& key, int value) { add(key, std::to_string(value)); }
    void add(const std::string& key, unsigned long long value) { add(key, std::to_string(value)); }
    void add(const std::string& key, unsigned long value) { add(key, std::to_string(value)); }
    void print() const;

   private:
    std::vector<std::pair<std::string, std::string>> kv_;
};

// Milliseconds since `t0`.
double msSince(std::chrono::steady_clock::time_point t0);

}  // namespace rtfact::app
