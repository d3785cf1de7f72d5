// Loading point clouds: PLY (ascii, binary little/big endian), PCD (ascii, binary,
// binary_compressed; through PCL after validating the header against the file size) and
// XYZ/PTS text. Every loader throws rtfact::Error(file, what) on bad input and drops
// points with non-finite coordinates (counted in droppedNonFinite).
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "points/point_cloud.h"

namespace rtfact::points {

// Points kept while loading (lidar users' --classes, --returns, --crop). Classes and
// returns need a file that has them (LAS/LAZ; PLY/PCD with a class/label field).
struct LoadFilter {
    std::vector<int> classes;  // empty: all
    enum class Returns { All, First, Last } returns = Returns::All;
    std::optional<std::array<double, 4>> crop;  // xmin, ymin, xmax, ymax in the file's coordinates
    bool active() const { return !classes.empty() || returns != Returns::All || crop.has_value(); }
};

// Loads any supported file, chosen by extension (.ply .pcd .xyz .pts .txt .las .laz).
PointCloud loadPointCloud(const std::string& file, const LoadFilter& filter = {});
// Keeps the points that pass `filter` (every per-point array follows); throws
// Error(file, ...) when the filter needs an attribute the cloud lacks or nothing is left.
void applyLoadFilter(PointCloud& cloud, const LoadFilter& filter, const std::string& file);
// Keeps the points i with keep[i] != 0, in order, in all of the cloud's arrays (freeing the rest).
void keepPoints(PointCloud& cloud, const std::vector<uint8_t>& keep);
// LAS 1.0-1.4 (formats 0-10) and LAZ; `threads` decode in parallel (0: all cores).
PointCloud loadLas(const std::string& file, const LoadFilter& filter = {}, int threads = 0);
// What a loaded cloud lost, as one line for a warning: "FILE: 12 points with non-finite
// coordinates dropped"; empty when nothing was dropped.
std::string droppedPointsMessage(const std::string& file, const PointCloud& cloud);
PointCloud loadPly(const std::string& file);
PointCloud loadPcd(const std::string& file);
PointCloud loadXyz(const std::string& file);

// What a header says, without reading the body: for `rtfact info`. nullopt when the
// file is not a point cloud (e.g. a PLY with faces).
struct PointFileInfo {
    std::string format;
    size_t points = 0;
    std::vector<std::string> properties;
};
std::optional<PointFileInfo> probePointFile(const std::string& file);

// Writes a binary little-endian PLY with x y z [nx ny nz] [red green blue] [radius].
void writePly(const std::string& file, const PointCloud& cloud);

}  // namespace rtfact::points
