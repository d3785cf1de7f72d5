// Loading point clouds: PLY (ascii, binary little/big endian), PCD (ascii, binary,
// binary_compressed; through PCL after validating the header against the file size) and
// XYZ/PTS text. Every loader throws rtfact::Error(file, what) on bad input and drops
// points with non-finite coordinates (counted in droppedNonFinite).
#pragma once
#include <optional>
#include <string>

#include "points/point_cloud.h"

namespace rtfact::points {

// Loads any supported file, chosen by extension (.ply .pcd .xyz .pts .txt).
PointCloud loadPointCloud(const std::string& file);
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
