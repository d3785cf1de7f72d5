#include "apps/rtfact/point_options.h"

#include <cmath>
#include <sstream>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/common_options.h"
#include "engine/usage_error.h"
#include "points/point_colors.h"

namespace rtfact::app {

namespace {

// "a,b,c": exactly `count` finite numbers (0: any count, at least one); throws UsageError.
std::vector<double> numberList(const std::string& text, size_t count, const std::string& option) {
    std::vector<double> v;
    std::stringstream ss(text);
    std::string part;
    while (std::getline(ss, part, ',')) {
        size_t used = 0;
        double x = 0;
        try {
            x = std::stod(part, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != part.size() || !std::isfinite(x))
            throw engine::UsageError(option, "'" + part + "' is not a number");
        v.push_back(x);
    }
    if ((count != 0 && v.size() != count) || v.empty())
        throw engine::UsageError(option, "expected " + (count ? std::to_string(count) : std::string("some")) +
                                             " comma-separated numbers, got '" + text + "'");
    return v;
}

// A CLI validator that runs `parse` (which throws UsageError) on the text.
template <class F>
CLI::Validator checkedBy(F parse) {
    return CLI::Validator(
        [parse](std::string& s) -> std::string {
            try {
                parse(s);
            } catch (const Error& e) {
                return e.what();
            }
            return {};
        },
        "");
}

std::array<float, 2> parseRange(const std::string& s) {
    const auto v = numberList(s, 2, "--range");
    if (!(v[1] > v[0])) throw engine::UsageError("--range", "lo must be below hi");
    return {float(v[0]), float(v[1])};
}

float parseEdl(const std::string& s) {
    if (s.empty() || s == "on") return 1.0f;
    if (s == "off") return 0.0f;
    const double x = numberList(s, 1, "--edl")[0];
    if (x < 0 || x > 100) throw engine::UsageError("--edl", "strength must be in [0, 100]");
    return float(x);
}

std::vector<int> parseClasses(const std::string& s) {
    std::vector<int> out;
    for (double x : numberList(s, 0, "--classes")) {
        if (x < 0 || x > 255 || x != std::floor(x))
            throw engine::UsageError("--classes", "classes are integers 0 to 255");
        out.push_back(int(x));
    }
    return out;
}

std::array<double, 4> parseCrop(const std::string& s) {
    const auto v = numberList(s, 4, "--crop");
    if (!(v[2] > v[0] && v[3] > v[1]))
        throw engine::UsageError("--crop", "expected xmin,ymin,xmax,ymax with min < max");
    return {v[0], v[1], v[2], v[3]};
}

}  // namespace

void PointOptions::addTo(CLI::App& cmd) {
    engine::PointSettings& ps = settings;
    auto* r =
        cmd.add_option("--radius", ps.radius, "Disc radius for every point (world units)")->check(positiveFinite());
    cmd.add_option("--radius-factor", ps.radiusFactor, "Scale of the radii (file radii or neighbour spacing)")
        ->capture_default_str()
        ->check(finiteRange(1e-3, 1e3))
        ->excludes(r);
    cmd.add_option("--normals", ps.normals, "auto|estimate|file")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "estimate", "file"}));
    cmd.add_option("--lod-quality", ps.lodQuality,
                   "Node answered by its representative disc when its size < footprint x Q (0: full detail)")
        ->capture_default_str()
        ->check(finiteRange(0.0, 64.0));
    cmd.add_option("--lod", lod, "on|off (off = full detail)")
        ->capture_default_str()
        ->check(CLI::IsMember({"on", "off"}));
    cmd.add_option("--color", color,
                   "auto|rgb|elevation|intensity|classification|return|attr:NAME|lod|normal (auto: the file's "
                   "colours if it has real ones, else elevation)")
        ->capture_default_str()
        ->check(checkedBy([](const std::string& s) { points::parseColorOptions(s); }));
    cmd.add_option("--colormap", ps.colormap,
                   joined(points::colormapNames()) + " (default: viridis; grayscale for intensity)")
        ->check(CLI::IsMember(points::colormapNames()));
    cmd.add_option("--range", range, "lo,hi: values mapped to the ends of the colormap (default: 2nd-98th percentile)")
        ->check(checkedBy(parseRange));
    edlOption = cmd.add_option("--edl", edl,
                               "Eye-dome lighting [STRENGTH] (default 1; 0 or off: none; on by default for clouds "
                               "without normals in the file)")
                    ->expected(0, 1)
                    ->check(checkedBy(parseEdl));
    cmd.add_option("--view", ps.view,
                   "Default camera: auto|top|oblique|front|side (auto: oblique for flat georeferenced clouds)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "top", "oblique", "front", "side"}));
    cmd.add_option("--classes", classes, "Load only these classes, e.g. 2,6 (ground, building)")
        ->check(checkedBy(parseClasses));
    cmd.add_option("--returns", returns, "Load first|last|all returns")
        ->capture_default_str()
        ->check(CLI::IsMember({"first", "last", "all"}));
    cmd.add_option("--crop", crop, "xmin,ymin,xmax,ymax: load only points inside (the file's coordinates)")
        ->check(checkedBy(parseCrop));
    cmd.add_option("--integrator", ps.integrator, joined(engine::pointIntegrators()))
        ->capture_default_str()
        ->check(CLI::IsMember(engine::pointIntegrators()));
    cmd.add_option("--ao-samples", ps.aoSamples, "AO rays per sample")
        ->capture_default_str()
        ->check(CLI::Range(1, 256));
    cmd.add_option("--leaf-size", ps.leafSize, "Maximum points per kd-tree leaf")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    cmd.add_option("--accel", ps.accel,
                   "Structure: kd (LoD kd-tree, ~31 bytes per point) | wide (wide BVH, ~65 bytes per point, "
                   "faster to trace)")
        ->capture_default_str()
        ->check(CLI::IsMember(engine::pointAccels()));
}

engine::Settings PointOptions::toSettings() const {
    engine::Settings s;
    s.points = settings;
    s.points.lod = lod == "on";
    const points::ColorOptions co = points::parseColorOptions(color);
    s.points.color = co.mode;
    s.points.colorAttribute = co.attribute;
    if (!range.empty()) s.points.colorRange = parseRange(range);
    if (edlOption && edlOption->count() > 0) s.points.edl = parseEdl(edl);
    return s;
}

points::LoadFilter PointOptions::loadFilter() const {
    points::LoadFilter f;
    if (!classes.empty()) f.classes = parseClasses(classes);
    if (returns == "first") f.returns = points::LoadFilter::Returns::First;
    if (returns == "last") f.returns = points::LoadFilter::Returns::Last;
    if (!crop.empty()) f.crop = parseCrop(crop);
    return f;
}

}  // namespace rtfact::app
