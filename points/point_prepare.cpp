// PCL lives here and in pcd_io.cpp only.
#include <pcl/console/print.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <thread>

#include "core/util/error.h"
#include "core/util/memory_budget.h"
#include "core/util/progress.h"
#include "points/huge_pages.h"
#include "points/point_prepare.h"

namespace rtfact::points {

namespace {
pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const std::vector<Vec3f>& pos) {
    auto c = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    c->resize(pos.size());
    for (size_t i = 0; i < pos.size(); ++i) (*c)[i] = pcl::PointXYZ(pos[i].x, pos[i].y, pos[i].z);
    c->width = uint32_t(pos.size());
    c->height = 1;
    c->is_dense = true;
    return c;
}
double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

std::vector<Vec3f> estimateNormals(const std::vector<Vec3f>& positions, int k, Vec3f viewpoint, int threads) {
    std::vector<Vec3f> out(positions.size(), Vec3f(0, 0, 1));
    if (positions.size() < 3) return out;
    auto cloud = toPcl(positions);
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // no PCL chatter on stderr
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(threads > 0 ? threads : int(std::thread::hardware_concurrency()));
    ne.setInputCloud(cloud);
    ne.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
    ne.setKSearch(std::max(3, std::min<int>(k, int(positions.size()))));
    ne.setViewPoint(viewpoint.x, viewpoint.y, viewpoint.z);
    pcl::PointCloud<pcl::Normal> normals;
    ne.compute(normals);
    for (size_t i = 0; i < positions.size() && i < normals.size(); ++i) {
        const Vec3f n(normals[i].normal_x, normals[i].normal_y, normals[i].normal_z);
        if (isFinite(n) && length(n) > 0.5f) out[i] = n;
        else out[i] = normalize(viewpoint - positions[i]);  // degenerate neighbourhood: face the viewer
        if (!(length(out[i]) > 0.5f)) out[i] = Vec3f(0, 0, 1);
    }
    return out;
}

std::vector<float> neighbourSpacing(const std::vector<Vec3f>& positions, int k) {
    std::vector<float> out(positions.size(), 0.0f);
    if (positions.size() <= size_t(k)) return out;
    auto cloud = toPcl(positions);
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(cloud);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, positions.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        pcl::Indices idx(size_t(k) + 1);
        std::vector<float> d2(size_t(k) + 1);
        for (size_t i = r.begin(); i < r.end(); ++i) {
            const int found = tree.nearestKSearch((*cloud)[i], k + 1, idx, d2);  // includes the point itself
            out[i] = found > 0 ? std::sqrt(d2[size_t(found - 1)]) : 0.0f;
        }
    });
    return out;
}

uint64_t pointPipelineBytes(uint64_t n, bool estimateNormals, bool estimateRadii) {
    // Peak resident memory measured with `rtfact points` on generated clouds of 0.5-4M
    // points, minus the mapped file: the cloud with normals and radii (28 B), its discs
    // (24 B) and the LoD tree with build temporaries come to ~66 B/point; PCL's normal
    // estimation (PointXYZ + Normal copies + FLANN tree) adds ~46 B/point, the spacing
    // k-NN (PointXYZ + FLANN tree) about half of that.
    uint64_t perPoint = 72;
    if (estimateNormals) perPoint += 48;
    else if (estimateRadii) perPoint += 24;
    return n * perPoint;
}

PrepareReport preparePointCloud(PointCloud& cloud, const PrepareOptions& opt, const std::string& file) {
    PrepareReport rep;
    const size_t n = cloud.size();
    const bool fileNormals = cloud.normals.size() == n;
    if (opt.normals == "file" && !fileNormals) throw Error(file, "--normals file: the file has no normals");
    const bool estimateN = opt.normals == "estimate" || !fileNormals;
    const bool estimateR = !(opt.radius > 0) && cloud.radii.size() != n;
    checkMemory(file, pointPipelineBytes(n, estimateN, estimateR),
                "preparing and building " + std::to_string(n) + " points",
                estimateN ? "normal estimation is the largest part: store normals in the file or subsample the cloud"
                          : "subsample the cloud, e.g. with pcl_voxel_grid");
    if (estimateN) {
        const auto t0 = std::chrono::steady_clock::now();
        Progress progress("normals", 1, progressEnabled());
        const Vec3f vp = cloud.hasViewpoint ? cloud.viewpoint : opt.viewpoint.value_or(cloud.bounds().center() + Vec3f(0, 0, 1e3f));
        cloud.normals = estimateNormals(cloud.positions, opt.normalK, vp, opt.threads);
        progress.finish();
        rep.normalsMs = msSince(t0);
        rep.estimatedNormals = true;
    }
    const auto t1 = std::chrono::steady_clock::now();
    if (opt.radius > 0) {
        cloud.radii.assign(n, opt.radius);
    } else if (cloud.radii.size() == n && std::any_of(cloud.radii.begin(), cloud.radii.end(), [](float r) { return r > 0; })) {
        for (float& r : cloud.radii) r *= opt.radiusFactor;
    } else {
        Progress progress("radii", 1, progressEnabled());
        std::vector<float> s = neighbourSpacing(cloud.positions, opt.radiusK);
        // Isolated points or duplicates: fall back to the median spacing.
        std::vector<float> sorted(s);
        std::nth_element(sorted.begin(), sorted.begin() + ptrdiff_t(sorted.size() / 2), sorted.end());
        float med = sorted.empty() ? 0.0f : sorted[sorted.size() / 2];
        if (!(med > 0)) {
            const AABB b = cloud.bounds();
            med = std::max(length(b.extent()), 1e-6f) * 1e-3f;
        }
        for (float& r : s) r = (r > 0 && r < 8 * med ? r : med) * opt.radiusFactor;
        cloud.radii = std::move(s);
        progress.finish();
        rep.estimatedRadii = true;
    }
    rep.radiusMs = msSince(t1);
    return rep;
}

ColorMode parseColorMode(const std::string& s) {
    if (s == "rgb") return ColorMode::Rgb;
    if (s == "intensity") return ColorMode::Intensity;
    if (s == "lod") return ColorMode::Lod;
    if (s == "normal") return ColorMode::Normal;
    throw Error("", "unknown colour mode '" + s + "'");
}

std::vector<Disc> makeDiscs(const PointCloud& c, ColorMode mode) {
    const size_t n = c.size();
    std::vector<Disc> d;
    resizeHuge(d, n);
    float iLo = 0, iHi = 1;
    if (mode == ColorMode::Intensity && c.intensities.size() == n) {
        iLo = *std::min_element(c.intensities.begin(), c.intensities.end());
        iHi = *std::max_element(c.intensities.begin(), c.intensities.end());
        if (!(iHi > iLo)) iHi = iLo + 1;
    }
    const bool hasC = c.colors.size() == n, hasI = c.intensities.size() == n;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
            d[i].center = c.positions[i];
            d[i].radius = c.radii.size() == n ? c.radii[i] : 0.0f;
            d[i].normal = encodeNormal(c.normals.size() == n ? c.normals[i] : Vec3f(0, 0, 1));
            Vec3f col(0.85f, 0.85f, 0.85f);
            if (mode == ColorMode::Rgb && hasC) col = Vec3f(c.colors[i][0], c.colors[i][1], c.colors[i][2]) * (1.0f / 255.0f);
            else if (mode == ColorMode::Intensity && hasI) col = Vec3f((c.intensities[i] - iLo) / (iHi - iLo));
            else if (mode == ColorMode::Intensity && hasC)
                col = Vec3f((0.299f * c.colors[i][0] + 0.587f * c.colors[i][1] + 0.114f * c.colors[i][2]) / 255.0f);
            d[i].rgba = packRGBA(col, 0);
        }
    });
    return d;
}

}  // namespace rtfact::points
