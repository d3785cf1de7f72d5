#include "apps/rtfact/point_options.h"

#include "apps/rtfact/commands.h"
#include "apps/rtfact/common_options.h"

namespace rtfact::app {

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
    cmd.add_option("--color", color, "rgb|intensity|lod|normal")
        ->capture_default_str()
        ->check(CLI::IsMember({"rgb", "intensity", "lod", "normal"}));
    cmd.add_option("--integrator", ps.integrator, joined(engine::pointIntegrators()))
        ->capture_default_str()
        ->check(CLI::IsMember(engine::pointIntegrators()));
    cmd.add_option("--ao-samples", ps.aoSamples, "AO rays per sample")
        ->capture_default_str()
        ->check(CLI::Range(1, 256));
    cmd.add_option("--leaf-size", ps.leafSize, "Maximum points per kd-tree leaf")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
}

engine::Settings PointOptions::toSettings() const {
    engine::Settings s;
    s.points = settings;
    s.points.lod = lod == "on";
    s.points.color = points::parseColorMode(color);
    return s;
}

}  // namespace rtfact::app
