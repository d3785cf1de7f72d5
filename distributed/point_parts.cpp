#include "distributed/point_parts.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <span>

#include "engine/usage_error.h"
#include "points/point_cloud_io.h"
#include "points/point_colors.h"
#include "points/point_prepare.h"

namespace rtfact::distributed {

namespace {

// Coordinate `axis` of p.
float coord(Vec3f p, int axis) { return axis == 0 ? p.x : axis == 1 ? p.y : p.z; }

// The whole cloud's colour mode and range, so that every part colours its points as the
// whole cloud would (a part's own percentiles differ).
void resolveColors(const points::PointCloud& c, engine::PointSettings& s) {
    s.color = points::resolveColorMode(c, s.color);
    if (s.colorRange) return;
    const size_t n = c.size();
    auto fix = [&](std::span<const float> v, double offset) {
        const std::array<float, 2> r = points::robustRange(v);
        s.colorRange = std::array<float, 2>{float(r[0] + offset), float(r[1] + offset)};
    };
    if (s.color == points::ColorMode::Elevation) {
        std::vector<float> z(n);
        for (size_t i = 0; i < n; ++i) z[i] = c.positions[i].z;
        fix(z, c.origin[2]);
    } else if (s.color == points::ColorMode::Intensity && c.intensities.size() == n) {
        fix(c.intensities, 0);
    } else if (s.color == points::ColorMode::Attribute) {
        const points::ScalarField* f = c.scalar(s.colorAttribute);
        if (!f) f = c.scalar("scalar_" + s.colorAttribute);
        if (f)
            fix(f->values, f->offset);
        else if (s.colorAttribute == "intensity" && c.intensities.size() == n)
            fix(c.intensities, 0);
    }
}

}  // namespace

PointPart loadPointPart(const std::string& file, const engine::OpenOptions& opt, const engine::Settings& s, int part,
                        int parts) {
    const auto t0 = std::chrono::steady_clock::now();
    PointPart p;
    p.file = file;
    p.part = part;
    p.parts = parts;
    p.settings = s;
    points::PointCloud c = points::loadPointCloud(file, opt.points);
    if (std::string w = points::droppedPointsMessage(file, c); !w.empty()) p.warnings.push_back(std::move(w));
    const size_t n = c.size();
    p.points = n;
    if (n < size_t(parts))
        throw engine::UsageError("--distribute", "data: " + std::to_string(n) + " points cannot be cut into " +
                                                     std::to_string(parts) + " parts");

    // The whole cloud's default view and eye-dome lighting, by the engine's rules for a
    // cloud with its box, georeference and attributes (a stand-in of two points).
    const AABB box = c.bounds();
    {
        points::PointCloud standIn;
        standIn.positions = {box.lo, box.hi};
        if (!c.normals.empty()) standIn.normals = {Vec3f(0, 0, 1), Vec3f(0, 0, 1)};
        standIn.origin = c.origin;
        standIn.crs = c.crs;
        const engine::Scene whole = engine::pointsFromCloud(std::move(standIn), file);
        p.view = whole.defaultView(s);
        p.edl = engine::eyeDomeStrength(whole, s);
    }
    resolveColors(c, p.settings.points);

    // Cells: the quantiles of the longest axis' coordinate.
    const Vec3f e = box.extent();
    p.axis = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
    {
        std::vector<float> v(n);
        for (size_t i = 0; i < n; ++i) v[i] = coord(c.positions[i], p.axis);
        auto quantile = [&](int k) {
            if (k <= 0) return -std::numeric_limits<float>::infinity();
            if (k >= parts) return std::numeric_limits<float>::infinity();
            const size_t at = size_t(uint64_t(n) * uint64_t(k) / uint64_t(parts));
            std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(at), v.end());
            return v[at];
        };
        p.lo = quantile(part);
        p.hi = quantile(part + 1);
    }
    const float ghost = kPointGhostFraction * std::max({e.x, e.y, e.z});
    std::vector<uint8_t> keep(n);
    p.isOwned.reserve(n / size_t(parts) + 1);
    for (size_t i = 0; i < n; ++i) {
        const float x = coord(c.positions[i], p.axis);
        const bool own = x >= p.lo && x < p.hi;
        keep[i] = own || (x >= p.lo - ghost && x < p.hi + ghost);
        if (keep[i]) p.isOwned.push_back(own);
        p.owned += own;
    }
    if (p.owned == 0)
        throw engine::UsageError("--distribute",
                                 "data: part " + std::to_string(part) + " of " + std::to_string(parts) +
                                     " is empty (too many points share one coordinate): use fewer ranks");
    p.ghosts = p.isOwned.size() - p.owned;
    points::keepPoints(c, keep);
    p.cloud = std::move(c);
    p.loadMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return p;
}

engine::Scene preparePointPart(PointPart& p, Vec3f eye, engine::Settings& settings) {
    settings = p.settings;
    engine::PointSettings& s = settings.points;
    // As the engine prepares the whole cloud for this camera (engine/render_points.cpp).
    points::PrepareOptions po;
    po.normals = s.normals;
    po.radius = s.radius;
    po.radiusFactor = s.radiusFactor;
    po.viewpoint = eye;
    points::preparePointCloud(p.cloud, po, p.file);
    points::keepPoints(p.cloud, p.isOwned);
    p.isOwned = {};
    // The prepared normals and radii are the part's "file" values, taken as they are.
    s.normals = "file";
    s.radius = 0;
    s.radiusFactor = 1;
    s.edl = 0.0f;
    return engine::pointsFromCloud(std::move(p.cloud), p.file);
}

}  // namespace rtfact::distributed
