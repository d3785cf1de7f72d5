// The load filters (--classes, --returns, --crop): one pass over the loaded cloud that
// keeps the points passing every filter, in order, in all of the cloud's arrays.
#include <algorithm>

#include "core/util/error.h"
#include "points/point_cloud_io.h"

namespace rtfact::points {

namespace {

template <class T>
void compact(std::vector<T>& v, const std::vector<uint8_t>& keep) {
    if (v.size() != keep.size()) return;
    size_t k = 0;
    for (size_t i = 0; i < v.size(); ++i)
        if (keep[i]) v[k++] = v[i];
    v.resize(k);
    v.shrink_to_fit();
}

}  // namespace

void applyLoadFilter(PointCloud& c, const LoadFilter& filter, const std::string& file) {
    if (!filter.active()) return;
    const size_t n = c.size();
    if (!filter.classes.empty() && c.classes.size() != n)
        throw Error(file, "--classes: the file has no classification");
    if (filter.returns != LoadFilter::Returns::All && (c.returnNumbers.size() != n || c.returnCounts.size() != n))
        throw Error(file, "--returns: the file has no return numbers");
    bool byClass[256] = {};
    for (int k : filter.classes)
        if (k >= 0 && k < 256) byClass[k] = true;
    std::vector<uint8_t> keep(n, 1);
    size_t kept = 0;
    for (size_t i = 0; i < n; ++i) {
        bool ok = filter.classes.empty() || byClass[c.classes[i]];
        if (filter.returns == LoadFilter::Returns::First) ok = ok && c.returnNumbers[i] <= 1;
        // The last return of its pulse (a single return is first and last).
        if (filter.returns == LoadFilter::Returns::Last) ok = ok && c.returnNumbers[i] >= c.returnCounts[i];
        if (filter.crop) {
            const auto& b = *filter.crop;
            const double x = double(c.positions[i].x) + c.origin[0], y = double(c.positions[i].y) + c.origin[1];
            ok = ok && x >= b[0] && x <= b[2] && y >= b[1] && y <= b[3];
        }
        keep[i] = ok;
        kept += ok;
    }
    if (kept == 0) throw Error(file, "no point passes --classes/--returns/--crop (of " + std::to_string(n) + ")");
    if (kept == n) return;
    keepPoints(c, keep);
}

void keepPoints(PointCloud& c, const std::vector<uint8_t>& keep) {
    compact(c.positions, keep);
    compact(c.normals, keep);
    compact(c.colors, keep);
    compact(c.radii, keep);
    compact(c.intensities, keep);
    compact(c.classes, keep);
    compact(c.returnNumbers, keep);
    compact(c.returnCounts, keep);
    for (ScalarField& s : c.scalars) compact(s.values, keep);
}

}  // namespace rtfact::points
