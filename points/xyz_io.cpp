// XYZ / PTS text clouds and the format dispatch. Columns per line:
//   3: x y z   4: x y z intensity   6: x y z nx ny nz (|values| <= 1) or x y z r g b
//   7: x y z intensity r g b (PTS)   9: x y z nx ny nz r g b
// A PTS file starts with a line holding the point count, checked against the file size.
#include <charconv>
#include <cmath>
#include <cstring>

#include "core/io/file_helpers.h"
#include "core/util/error.h"
#include "points/point_cloud_io.h"
#include "points/point_cloud_io_detail.h"

namespace rtfact::points {
using namespace detail;

namespace {

// Splits one line into numbers; returns false on a non-number token.
bool parseLine(const char* p, const char* end, std::vector<double>& vals) {
    vals.clear();
    while (p < end) {
        while (p < end && (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r')) ++p;
        if (p >= end) break;
        const char* s = p;
        while (p < end && !(*p == ' ' || *p == '\t' || *p == ',' || *p == '\r')) ++p;
        double v;
        auto [q, ec] = std::from_chars(s, p, v);
        if (ec != std::errc{} || q != p) {
            const std::string_view t(s, size_t(p - s));
            if (t == "nan" || t == "NaN" || t == "-nan" || t == "inf" || t == "-inf")
                v = std::nan("");
            else
                return false;
        }
        vals.push_back(v);
    }
    return true;
}

struct XyzLayout {
    size_t columns = 0;
    bool pts = false;
    uint64_t declared = 0;
    size_t firstLine = 0;  // byte offset of the first data line
};

XyzLayout detect(const MappedFile& f) {
    XyzLayout L;
    std::vector<double> vals;
    size_t pos = 0;
    int lineNo = 0;
    while (pos < f.size()) {
        size_t eol = pos;
        while (eol < f.size() && f.data()[eol] != '\n') ++eol;
        const size_t start = pos;
        pos = std::min(eol + 1, f.size());
        if (eol - start > 4096) throw Error(f.name(), "line too long for an XYZ/PTS file");
        if (!parseLine(f.data() + start, f.data() + eol, vals))
            throw Error(f.name(), "line " + std::to_string(lineNo + 1) + " is not a list of numbers");
        ++lineNo;
        if (vals.empty()) continue;
        if (lineNo == 1 && vals.size() == 1) {
            // Compare as double before converting: a count beyond 2^53 cannot be a real file.
            if (!(vals[0] >= 0) || vals[0] != std::floor(vals[0]) || vals[0] > 9.0e15)
                throw Error(f.name(), "bad PTS point count");
            L.pts = true;
            L.declared = uint64_t(vals[0]);
            if (L.declared == 0) throw Error(f.name(), "empty point cloud (count 0)");
            if (L.declared > (f.size() - pos) / 6)
                throw Error(f.name(),
                            "PTS header declares " + std::to_string(L.declared) + " points but the file is too small");
            continue;
        }
        if (vals.size() < 3) throw Error(f.name(), "line " + std::to_string(lineNo) + " has fewer than 3 values");
        L.columns = vals.size();
        L.firstLine = start;
        return L;
    }
    throw Error(f.name(), "empty point cloud (no data lines)");
}

}  // namespace

std::optional<PointFileInfo> probeXyz(const std::string& file) {
    MappedFile f(file);
    XyzLayout L = detect(f);
    PointFileInfo info;
    info.format = L.pts ? "pts text" : "xyz text";
    size_t lines = 0;
    for (size_t i = L.firstLine; i < f.size(); ++i) lines += f.data()[i] == '\n';
    info.points = L.pts ? L.declared : lines + (f.size() > 0 && f.data()[f.size() - 1] != '\n');
    info.properties = {"x", "y", "z"};
    return info;
}

PointCloud loadXyz(const std::string& file) {
    MappedFile f(file);
    const XyzLayout L = detect(f);
    const size_t cols = L.columns;
    std::vector<double> vals;
    // Column meaning from the first line.
    parseLine(f.data() + L.firstLine, std::find(f.data() + L.firstLine, f.data() + f.size(), '\n'), vals);
    bool normals = false, colors = false, intensity = false;
    size_t nOff = 0, cOff = 0, iOff = 0;
    if (cols == 4)
        intensity = true, iOff = 3;
    else if (cols == 6) {
        if (std::fabs(vals[3]) <= 1 && std::fabs(vals[4]) <= 1 && std::fabs(vals[5]) <= 1)
            normals = true, nOff = 3;
        else
            colors = true, cOff = 3;
    } else if (cols == 7)
        intensity = true, iOff = 3, colors = true, cOff = 4;
    else if (cols >= 9)
        normals = true, nOff = 3, colors = true, cOff = 6;
    PointCloud cloud;
    cloud.format = L.pts ? "pts text" : "xyz text";
    cloud.properties = {"x", "y", "z"};
    if (normals) cloud.properties.insert(cloud.properties.end(), {"nx", "ny", "nz"});
    if (intensity) cloud.properties.push_back("intensity");
    if (colors) cloud.properties.insert(cloud.properties.end(), {"red", "green", "blue"});
    PointSink sink;
    // A point line needs at least 6 bytes ("0 0 0\n"): bound the allocation by the file.
    const size_t bound = (f.size() - L.firstLine) / 6 + 1;
    sink.pos.reserve(L.pts ? std::min<size_t>(L.declared, bound) : std::min<size_t>(bound, 1 << 20));
    size_t pos = L.firstLine, lineNo = 0;
    while (pos < f.size()) {
        size_t eol = pos;
        while (eol < f.size() && f.data()[eol] != '\n') ++eol;
        const size_t start = pos;
        pos = std::min(eol + 1, f.size());
        ++lineNo;
        if (!parseLine(f.data() + start, f.data() + eol, vals))
            throw Error(file, "data line " + std::to_string(lineNo) + " is not a list of numbers");
        if (vals.empty()) continue;
        if (vals.size() != cols)
            throw Error(file, "data line " + std::to_string(lineNo) + " has " + std::to_string(vals.size()) +
                                  " values, expected " + std::to_string(cols));
        sink.pos.push_back({vals[0], vals[1], vals[2]});
        if (normals) sink.nrm.push_back(Vec3f(float(vals[nOff]), float(vals[nOff + 1]), float(vals[nOff + 2])));
        if (colors)
            sink.col.push_back({colorByte(vals[cOff], ScalarType::U8), colorByte(vals[cOff + 1], ScalarType::U8),
                                colorByte(vals[cOff + 2], ScalarType::U8)});
        if (intensity) sink.inten.push_back(float(vals[iOff]));
    }
    if (L.pts && sink.pos.size() != L.declared)
        throw Error(file, "PTS header declares " + std::to_string(L.declared) + " points but the file holds " +
                              std::to_string(sink.pos.size()) + " (truncated?)");
    sink.finish(file, cloud);
    return cloud;
}

using io::lowerExt;

PointCloud loadPointCloud(const std::string& file, const LoadFilter& filter) {
    const std::string e = lowerExt(file);
    if (e == ".las" || e == ".laz") return loadLas(file, filter);
    PointCloud c;
    if (e == ".ply")
        c = loadPly(file);
    else if (e == ".pcd")
        c = loadPcd(file);
    else if (e == ".xyz" || e == ".pts" || e == ".txt" || e == ".asc")
        c = loadXyz(file);
    else
        throw Error(file, "unknown point cloud format '" + e + "' (expected .ply, .pcd, .xyz, .pts, .las, .laz)");
    applyLoadFilter(c, filter, file);
    return c;
}

std::string droppedPointsMessage(const std::string& file, const PointCloud& cloud) {
    const size_t n = cloud.droppedNonFinite;
    if (n == 0) return {};
    return file + ": " + std::to_string(n) + (n == 1 ? " point" : " points") + " with non-finite coordinates dropped";
}

std::optional<PointFileInfo> probePointFile(const std::string& file) {
    const std::string e = lowerExt(file);
    if (e == ".ply") return probePly(file);
    if (e == ".pcd") return probePcd(file);
    if (e == ".xyz" || e == ".pts") return probeXyz(file);
    if (e == ".las" || e == ".laz") return probeLas(file);
    return std::nullopt;
}

}  // namespace rtfact::points
