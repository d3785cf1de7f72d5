// PCL lives here and in pcd_io.cpp only.
#include "points/point_prepare.h"

#include <pcl/console/print.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <thread>

#include "core/util/error.h"
#include "core/util/huge_pages.h"
#include "core/util/memory_budget.h"
#include "core/util/progress.h"

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

// Exact duplicate positions collapsed to one. FLANN's k-NN search descends into every
// subtree not strictly farther than the current k-th distance: once a query has found k
// copies of its own position that distance is 0, every subtree holding another copy is at
// distance 0 too, and each query visits all copies (quadratic: 100,000 copies took 52 s).
// The searches run on the distinct positions and their results are mapped back.
struct DistinctPositions {
    std::vector<Vec3f> positions;  // first occurrences in input order; empty when all are distinct
    std::vector<uint32_t> slot;    // point i -> index in `positions`; empty when all are distinct
    bool collapsed() const { return !slot.empty(); }
    const std::vector<Vec3f>& of(const std::vector<Vec3f>& input) const { return collapsed() ? positions : input; }
    // Per-distinct-position values -> per-point values.
    template <class T>
    std::vector<T> expand(std::vector<T> v) const {
        if (!collapsed()) return v;
        std::vector<T> out(slot.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, slot.size(), 1 << 14),
                          [&](const tbb::blocked_range<size_t>& r) {
                              for (size_t i = r.begin(); i < r.end(); ++i) out[i] = v[slot[i]];
                          });
        return out;
    }
};

DistinctPositions collapseDuplicates(const std::vector<Vec3f>& pos) {
    const size_t n = pos.size();
    DistinctPositions d;
    if (n < 2) return d;
    if (n > UINT32_MAX) throw Error("", "more than 2^32 points");  // PCL's int indices stop earlier
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    // Equal positions become neighbours, the first occurrence leading its group.
    tbb::parallel_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        const Vec3f p = pos[a], q = pos[b];
        if (p.x != q.x) return p.x < q.x;
        if (p.y != q.y) return p.y < q.y;
        if (p.z != q.z) return p.z < q.z;
        return a < b;
    });
    std::vector<uint32_t> slot(n);
    uint32_t head = order[0];
    for (size_t k = 0; k < n; ++k) {
        if (!(pos[order[k]] == pos[head])) head = order[k];
        slot[order[k]] = head;  // first occurrence of the position
    }
    order = {};
    // Number the first occurrences in input order (a head precedes its copies).
    uint32_t m = 0;
    for (size_t i = 0; i < n; ++i) slot[i] = slot[i] == i ? m++ : slot[slot[i]];
    if (m == n) return d;
    d.positions.resize(m);
    for (size_t i = 0; i < n; ++i) d.positions[slot[i]] = pos[i];
    d.slot = std::move(slot);
    return d;
}

// Normals of distinct positions (see estimateNormals).
std::vector<Vec3f> normalsOfDistinct(const std::vector<Vec3f>& positions, int k, Vec3f viewpoint, int threads) {
    std::vector<Vec3f> out(positions.size());
    const auto faceViewer = [&](size_t i) {
        const Vec3f v = normalize(viewpoint - positions[i]);
        return length(v) > 0.5f ? v : Vec3f(0, 0, 1);
    };
    if (positions.size() < 3) {  // no plane through fewer than three positions
        for (size_t i = 0; i < positions.size(); ++i) out[i] = faceViewer(i);
        return out;
    }
    auto cloud = toPcl(positions);
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // no PCL chatter on stderr
    pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> ne(threads > 0 ? threads
                                                                        : int(std::thread::hardware_concurrency()));
    ne.setInputCloud(cloud);
    ne.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
    ne.setKSearch(std::max(3, std::min<int>(k, int(positions.size()))));
    ne.setViewPoint(viewpoint.x, viewpoint.y, viewpoint.z);
    pcl::PointCloud<pcl::Normal> normals;
    ne.compute(normals);
    for (size_t i = 0; i < positions.size(); ++i) {
        const Vec3f n =
            i < normals.size() ? Vec3f(normals[i].normal_x, normals[i].normal_y, normals[i].normal_z) : Vec3f(0.0f);
        out[i] = isFinite(n) && length(n) > 0.5f ? n : faceViewer(i);  // degenerate neighbourhood: face the viewer
    }
    return out;
}

// Spacing of distinct positions (see neighbourSpacing).
std::vector<float> spacingOfDistinct(const std::vector<Vec3f>& positions, int k) {
    std::vector<float> out(positions.size(), 0.0f);
    if (positions.size() < 2) return out;
    // A tiny cloud (at most k positions) has no k-th neighbour and no surface to close:
    // half the distance to the nearest other position keeps each point's disc apart.
    const bool tiny = positions.size() <= size_t(std::max(k, 1));
    const int kk = tiny ? 1 : std::max(k, 1);
    const float scale = tiny ? 0.5f : 1.0f;
    auto cloud = toPcl(positions);
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(cloud);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, positions.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        pcl::Indices idx(size_t(kk) + 1);
        std::vector<float> d2(size_t(kk) + 1);
        for (size_t i = r.begin(); i < r.end(); ++i) {
            const int found = tree.nearestKSearch((*cloud)[i], kk + 1, idx, d2);  // includes the point itself
            out[i] = found > 0 ? scale * std::sqrt(d2[size_t(found - 1)]) : 0.0f;
        }
    });
    return out;
}
}  // namespace

std::vector<Vec3f> estimateNormals(const std::vector<Vec3f>& positions, int k, Vec3f viewpoint, int threads) {
    const DistinctPositions d = collapseDuplicates(positions);
    return d.expand(normalsOfDistinct(d.of(positions), k, viewpoint, threads));
}

std::vector<float> neighbourSpacing(const std::vector<Vec3f>& positions, int k) {
    const DistinctPositions d = collapseDuplicates(positions);
    return d.expand(spacingOfDistinct(d.of(positions), k));
}

uint64_t pointPipelineBytes(uint64_t n, bool estimateNormals, bool estimateRadii) {
    // Peak resident memory measured with `rtfact points` on generated clouds of 0.5-4M
    // points, minus the mapped file: the cloud with normals and radii (28 B), its discs
    // (24 B) and the LoD tree with build temporaries come to ~66 B/point; PCL's normal
    // estimation (PointXYZ + Normal copies + FLANN tree) adds ~46 B/point, the spacing
    // k-NN (PointXYZ + FLANN tree) about half of that. Collapsing duplicates before
    // either keeps a slot per point and a copy of the distinct positions (16 B).
    uint64_t perPoint = 72;
    if (estimateNormals)
        perPoint += 48;
    else if (estimateRadii)
        perPoint += 24;
    if (estimateNormals || estimateRadii) perPoint += 16;
    return n * perPoint;
}

PrepareReport preparePointCloud(PointCloud& cloud, const PrepareOptions& opt, const std::string& file) {
    PrepareReport rep;
    const size_t n = cloud.size();
    const bool fileNormals = cloud.normals.size() == n;
    if (opt.normals == "file" && !fileNormals) throw Error(file, "--normals file: the file has no normals");
    const bool estimateN = opt.normals == "estimate" || !fileNormals;
    const bool fileRadii =
        cloud.radii.size() == n && std::any_of(cloud.radii.begin(), cloud.radii.end(), [](float r) { return r > 0; });
    const bool estimateR = !(opt.radius > 0) && !fileRadii;  // --radius or the file's radii: no spacing search
    checkMemory(file, pointPipelineBytes(n, estimateN, estimateR),
                "preparing and building " + std::to_string(n) + " points",
                estimateN ? "normal estimation is the largest part: store normals in the file or subsample the cloud"
                          : "subsample the cloud, e.g. with pcl_voxel_grid");
    // One collapse of the duplicate positions serves both k-NN searches.
    const auto t0 = std::chrono::steady_clock::now();
    DistinctPositions distinct;
    if (estimateN || estimateR) distinct = collapseDuplicates(cloud.positions);
    const std::vector<Vec3f>& searched = distinct.of(cloud.positions);
    if (estimateN) {
        Progress progress("normals", 1, progressEnabled());
        const Vec3f vp =
            cloud.hasViewpoint ? cloud.viewpoint : opt.viewpoint.value_or(cloud.bounds().center() + Vec3f(0, 0, 1e3f));
        cloud.normals = distinct.expand(normalsOfDistinct(searched, opt.normalK, vp, opt.threads));
        progress.finish();
        rep.normalsMs = msSince(t0);
        rep.estimatedNormals = true;
    }
    const auto t1 = std::chrono::steady_clock::now();
    if (opt.radius > 0) {
        cloud.radii.assign(n, opt.radius);
    } else if (fileRadii) {
        for (float& r : cloud.radii) r *= opt.radiusFactor;
    } else {
        Progress progress("radii", 1, progressEnabled());
        std::vector<float> s = spacingOfDistinct(searched, opt.radiusK);
        // Isolated points (spacing far above the median) get the median spacing.
        std::vector<float> sorted(s);
        std::nth_element(sorted.begin(), sorted.begin() + ptrdiff_t(sorted.size() / 2), sorted.end());
        float med = sorted.empty() ? 0.0f : sorted[sorted.size() / 2];
        if (!(med > 0)) {
            // One distinct position has no spacing to measure: size its disc from the camera
            // (a dot about a tenth of a 45 degree view wide), else from its coordinates.
            const Vec3f p = cloud.positions.empty() ? Vec3f(0.0f) : cloud.positions[0];
            std::optional<Vec3f> eye = opt.viewpoint;
            if (!eye && cloud.hasViewpoint) eye = cloud.viewpoint;
            med = eye ? 0.05f * length(*eye - p) : 0.0f;
            if (!(med > 0) || !std::isfinite(med))
                med = 1e-3f * std::max({1.0f, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
        }
        for (float& r : s) r = (r > 0 && r < 8 * med ? r : med) * opt.radiusFactor;
        cloud.radii = distinct.expand(std::move(s));
        progress.finish();
        rep.estimatedRadii = true;
    }
    rep.radiusMs = msSince(t1);
    return rep;
}

ColorMode parseColorMode(const std::string& s) { return parseColorOptions(s).mode; }

std::vector<Disc> makeDiscs(const PointCloud& c, ColorMode mode) {
    ColorOptions o;
    o.mode = mode;
    return makeDiscs(c, o);
}

std::vector<Disc> makeDiscs(const PointCloud& c, const ColorOptions& color, const std::string& source) {
    const size_t n = c.size();
    const std::vector<Vec3f> col = pointColors(c, color, source);
    std::vector<Disc> d;
    resizeFreshHugePages(d, n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
            d[i].center = c.positions[i];
            d[i].radius = c.radii.size() == n ? c.radii[i] : 0.0f;
            d[i].normal = encodeNormal(c.normals.size() == n ? c.normals[i] : Vec3f(0, 0, 1));
            d[i].rgba = packRGBA(col[i], 0);
        }
    });
    return d;
}

}  // namespace rtfact::points
