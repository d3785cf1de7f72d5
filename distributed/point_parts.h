// One rank's part of a point cloud for data-parallel rendering (docs/mpi.md). The cloud
// is cut into P cells along its longest axis at the quantiles of that coordinate (about
// n/P points each); a rank keeps the points whose centre lies in its cell. Normals and
// radii are estimated from k nearest neighbours, so a rank prepares its points together
// with a ghost margin of its neighbours' points and then drops the ghosts; colours use the
// whole cloud's mode and range. The parts' discs may reach across the cell borders: depth
// compositing takes the nearest hit, so the borders leave no seams. No MPI here: every
// rank computes the same cells from the same file.
#pragma once
#include <string>
#include <vector>

#include "engine/render_session.h"
#include "engine/scene.h"
#include "engine/settings.h"
#include "points/point_cloud.h"

namespace rtfact::distributed {

// Ghost margin around a cell, as a fraction of the cloud's longest extent: wider than the
// neighbourhoods normal (24 neighbours) and radius (4) estimation search in any cloud
// dense enough to render as a surface.
inline constexpr float kPointGhostFraction = 0.03f;

struct PointPart {
    std::string file;
    int part = 0, parts = 1;
    int axis = 0;                  // the cut axis (0 x, 1 y, 2 z)
    float lo = 0, hi = 0;          // the cell: lo <= coordinate < hi (infinite at the ends)
    uint64_t points = 0;           // the whole cloud's
    uint64_t owned = 0;            // points in this cell
    uint64_t ghosts = 0;           // neighbours' points prepared with them (then dropped)
    points::PointCloud cloud;      // owned and ghost points, until preparePointPart
    std::vector<uint8_t> isOwned;  // per point of `cloud`
    engine::Settings settings;     // the whole cloud's colour mode and range resolved
    engine::DefaultView view;      // the whole cloud's default view for the settings
    float edl = 0;                 // the whole cloud's eye-dome lighting strength
    std::vector<std::string> warnings;
    double loadMs = 0;
};

// Reads `file` (the loaders read whole: the whole cloud is held only while it is cut)
// and keeps part `part` of `parts` with its ghosts; throws Error (unreadable file) or
// UsageError (fewer points than parts, or a cloud that does not cut into `parts` cells).
PointPart loadPointPart(const std::string& file, const engine::OpenOptions& opt, const engine::Settings& s, int part,
                        int parts);

// Prepares the part for a camera at `eye` (as the whole cloud would be prepared for it),
// drops the ghosts and returns the owned points as a scene; `settings` becomes what it
// renders with (prepared normals and radii, no eye-dome lighting: that is applied to the
// composited image).
engine::Scene preparePointPart(PointPart& p, Vec3f eye, engine::Settings& settings);

}  // namespace rtfact::distributed
