// Preparing a loaded cloud for splatting: normals (from the file or estimated with
// PCL's multi-threaded k-NN NormalEstimationOMP, oriented towards the sensor or camera)
// and per-point radii from the local spacing (distance to the k-th nearest neighbour
// times a factor, so that neighbouring discs overlap and close the surface).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "points/disc.h"
#include "points/point_cloud.h"
#include "points/point_colors.h"

namespace rtfact::points {

struct PrepareOptions {
    std::string normals = "auto";    // auto: from the file if present, else estimate | estimate | file
    int normalK = 24;                // noisy depth sensors need a wide neighbourhood
    float radius = 0.0f;             // > 0: the same radius for every point
    float radiusFactor = 1.0f;       // times the spacing estimate (or times the file's radii)
    int radiusK = 4;                 // neighbour whose distance is the spacing
    std::optional<Vec3f> viewpoint;  // where normals should face when there is no sensor position
    int threads = 0;                 // 0: all cores
};

struct PrepareReport {
    double normalsMs = 0, radiusMs = 0;
    bool estimatedNormals = false, estimatedRadii = false;
};

// Peak bytes that preparing a cloud of n points and building its LoD tree need
// (calibrated on measured peaks); preparePointCloud checks it against the machine first.
uint64_t pointPipelineBytes(uint64_t n, bool estimateNormals, bool estimateRadii);

// Fills cloud.normals and cloud.radii (throws rtfact::Error on impossible requests,
// e.g. --normals file for a file without normals).
PrepareReport preparePointCloud(PointCloud& cloud, const PrepareOptions& opt, const std::string& file);

// Both k-NN estimates below treat copies of a position as one point (duplicates are
// collapsed before the search and the results copied back to every copy).
// Normal estimation alone (k nearest neighbours, PCA), oriented towards `viewpoint`;
// points without a plane (fewer than three distinct positions) face the viewpoint.
std::vector<Vec3f> estimateNormals(const std::vector<Vec3f>& positions, int k, Vec3f viewpoint, int threads = 0);
// Distance from each point to its k-th nearest other position; in a cloud of at most k
// positions half the distance to the nearest other one (discs that touch, not cover each
// other); 0 when all points coincide.
std::vector<float> neighbourSpacing(const std::vector<Vec3f>& positions, int k);

// The mode of a --color value (see parseColorOptions).
ColorMode parseColorMode(const std::string& s);

// Discs from a prepared cloud, coloured by pointColors (white for lod/normal: colours
// computed at shading time).
std::vector<Disc> makeDiscs(const PointCloud& cloud, const ColorOptions& color, const std::string& source = "");
std::vector<Disc> makeDiscs(const PointCloud& cloud, ColorMode mode);

}  // namespace rtfact::points
