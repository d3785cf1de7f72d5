#include "python/array_input.h"

#include <cmath>
#include <cstring>

#include "python/errors.h"

namespace py = pybind11;

namespace rtfact::python {

namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f is three packed floats (memcpy from N x 3 float32)");

// The scalar types the module reads in place.
enum class Scalar { F32, F64, U8, U16, I16, I32, I64, U32, U64, Other };

template <class T>
bool isType(const py::array& a) {
    return a.dtype().equal(py::dtype::of<T>());
}

Scalar scalarOf(const py::array& a) {
    if (isType<float>(a)) return Scalar::F32;
    if (isType<double>(a)) return Scalar::F64;
    if (isType<uint8_t>(a)) return Scalar::U8;
    if (isType<uint16_t>(a)) return Scalar::U16;
    if (isType<int16_t>(a)) return Scalar::I16;
    if (isType<int32_t>(a)) return Scalar::I32;
    if (isType<int64_t>(a)) return Scalar::I64;
    if (isType<uint32_t>(a)) return Scalar::U32;
    if (isType<uint64_t>(a)) return Scalar::U64;
    return Scalar::Other;
}

std::string dtypeName(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

std::string shapeText(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

// Any array-like as a numpy array (lists too); ValueError when numpy cannot make one.
py::array asArray(py::handle obj, const char* what) {
    py::array a = py::array::ensure(obj);
    if (!a) {
        PyErr_Clear();
        throwValue(what, "expected a numpy array (or something numpy.asarray accepts)");
    }
    return a;
}

// A 2D array view read through its strides without the GIL.
struct Rows {
    const uint8_t* data = nullptr;
    size_t n = 0;
    int64_t rowStride = 0, colStride = 0;
    Scalar type = Scalar::Other;

    template <class T>
    T get(size_t i, int c) const {
        T v;
        std::memcpy(&v, data + int64_t(i) * rowStride + int64_t(c) * colStride, sizeof v);
        return v;
    }
    double value(size_t i, int c) const {
        switch (type) {
            case Scalar::F32:
                return get<float>(i, c);
            case Scalar::U8:
                return get<uint8_t>(i, c);
            default:
                return get<double>(i, c);
        }
    }
    bool contiguousF32x3() const { return type == Scalar::F32 && colStride == 4 && rowStride == 12; }
};

// An N x cols (cols > 1) or N (cols == 1) array of one of `allowed` types.
Rows rowsOf(const py::array& a, const char* what, int cols, std::initializer_list<Scalar> allowed, const char* typeText,
            size_t expectRows = 0) {
    const bool vector = cols == 1;
    if (vector ? a.ndim() != 1 : (a.ndim() != 2 || a.shape(1) != cols))
        throwValue(what, std::string("expected an ") + (vector ? "array of N values" : "N x 3 array") + ", got shape " +
                             shapeText(a));
    Rows r;
    r.type = scalarOf(a);
    if (std::find(allowed.begin(), allowed.end(), r.type) == allowed.end())
        throwValue(what, "dtype " + dtypeName(a) + " is not " + typeText);
    r.n = size_t(a.shape(0));
    if (r.n == 0) throwValue(what, "empty array");
    if (expectRows && r.n != expectRows)
        throwValue(what, "has " + std::to_string(r.n) + " rows for " + std::to_string(expectRows) + " points");
    r.data = static_cast<const uint8_t*>(a.data());
    r.rowStride = a.strides(0);
    r.colStride = vector ? 0 : a.strides(1);
    return r;
}

std::vector<Vec3f> vec3s(const Rows& r) {
    std::vector<Vec3f> out(r.n);
    if (r.contiguousF32x3()) {
        std::memcpy(out.data(), r.data, r.n * sizeof(Vec3f));
        return out;
    }
    for (size_t i = 0; i < r.n; ++i) out[i] = Vec3f(float(r.value(i, 0)), float(r.value(i, 1)), float(r.value(i, 2)));
    return out;
}

bool isNone(py::handle h) { return !h || h.is_none(); }

}  // namespace

engine::Scene pointsFromNumpy(py::handle xyzObj, py::handle colorsObj, py::handle normalsObj, py::handle radiusObj,
                              py::handle intensityObj) {
    const py::array xyz = asArray(xyzObj, "xyz");
    const Rows p = rowsOf(xyz, "xyz", 3, {Scalar::F32, Scalar::F64}, "float32 or float64");
    py::array colors, normals, radius, intensity;
    Rows c, nr, rad, in;
    float fixedRadius = 0;
    if (!isNone(colorsObj)) {
        colors = asArray(colorsObj, "colors");
        c = rowsOf(colors, "colors", 3, {Scalar::U8, Scalar::F32, Scalar::F64}, "uint8 (0..255) or float (0..1)", p.n);
    }
    if (!isNone(normalsObj)) {
        normals = asArray(normalsObj, "normals");
        nr = rowsOf(normals, "normals", 3, {Scalar::F32, Scalar::F64}, "float32 or float64", p.n);
    }
    if (!isNone(radiusObj)) {
        if (py::isinstance<py::float_>(radiusObj) || py::isinstance<py::int_>(radiusObj)) {
            fixedRadius = radiusObj.cast<float>();
            if (!(std::isfinite(fixedRadius) && fixedRadius > 0)) throwValue("radius", "must be positive and finite");
        } else {
            radius = asArray(radiusObj, "radius");
            rad = rowsOf(radius, "radius", 1, {Scalar::F32, Scalar::F64}, "float32 or float64", p.n);
        }
    }
    if (!isNone(intensityObj)) {
        intensity = asArray(intensityObj, "intensity");
        in = rowsOf(intensity, "intensity", 1, {Scalar::F32, Scalar::F64, Scalar::U8}, "float or uint8", p.n);
    }
    py::gil_scoped_release noGil;
    points::PointCloud cloud;
    if (p.type == Scalar::F64) {
        // Large (e.g. UTM) coordinates: shifted in double by a rounded origin, as the file
        // loaders do, so that float32 keeps their precision.
        std::array<double, 3> o{0, 0, 0};
        const double x = p.get<double>(0, 0), y = p.get<double>(0, 1), z = p.get<double>(0, 2);
        if (std::max({std::fabs(x), std::fabs(y), std::fabs(z)}) > 1e4 && std::isfinite(x + y + z))
            o = {std::round(x), std::round(y), std::round(z)};
        cloud.origin = o;
        cloud.positions.resize(p.n);
        for (size_t i = 0; i < p.n; ++i)
            cloud.positions[i] = Vec3f(float(p.get<double>(i, 0) - o[0]), float(p.get<double>(i, 1) - o[1]),
                                       float(p.get<double>(i, 2) - o[2]));
    } else {
        cloud.positions = vec3s(p);
    }
    if (c.data) {
        cloud.colors.resize(c.n);
        for (size_t i = 0; i < c.n; ++i)
            for (int k = 0; k < 3; ++k) {
                if (c.type == Scalar::U8) {
                    cloud.colors[i][size_t(k)] = c.get<uint8_t>(i, k);
                    continue;
                }
                const double v = c.value(i, k);
                if (!std::isfinite(v)) {
                    throwValue("colors", "non-finite value at point " + std::to_string(i));
                }
                cloud.colors[i][size_t(k)] = uint8_t(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5);
            }
    }
    if (nr.data) cloud.normals = vec3s(nr);
    if (rad.data) {
        cloud.radii.resize(rad.n);
        for (size_t i = 0; i < rad.n; ++i) cloud.radii[i] = float(rad.value(i, 0));
    } else if (fixedRadius > 0) {
        cloud.radii.assign(p.n, fixedRadius);
    }
    if (in.data) {
        cloud.intensities.resize(in.n);
        for (size_t i = 0; i < in.n; ++i) cloud.intensities[i] = float(in.value(i, 0));
    }
    return engine::pointsFromCloud(std::move(cloud), "points");
}

engine::Scene meshFromNumpy(py::handle verticesObj, py::handle facesObj) {
    const py::array vertices = asArray(verticesObj, "vertices");
    const py::array faces = asArray(facesObj, "faces");
    const Rows v = rowsOf(vertices, "vertices", 3, {Scalar::F32, Scalar::F64}, "float32 or float64");
    const Rows f = rowsOf(faces, "faces", 3, {Scalar::I32, Scalar::I64, Scalar::U32, Scalar::U64}, "an integer type");
    std::vector<Vec3f> positions;
    std::vector<uint32_t> indices(f.n * 3);
    {
        py::gil_scoped_release noGil;
        positions = vec3s(v);
        for (size_t i = 0; i < f.n; ++i)
            for (int k = 0; k < 3; ++k) {
                int64_t idx;
                switch (f.type) {
                    case Scalar::I32:
                        idx = f.get<int32_t>(i, k);
                        break;
                    case Scalar::U32:
                        idx = f.get<uint32_t>(i, k);
                        break;
                    case Scalar::U64:
                        idx = int64_t(std::min<uint64_t>(f.get<uint64_t>(i, k), uint64_t(INT64_MAX)));
                        break;
                    default:
                        idx = f.get<int64_t>(i, k);
                }
                if (idx < 0 || uint64_t(idx) >= positions.size()) {
                    throwValue("faces", "index " + std::to_string(idx) + " in face " + std::to_string(i) +
                                            " is outside the " + std::to_string(positions.size()) + " vertices");
                }
                indices[i * 3 + size_t(k)] = uint32_t(idx);
            }
        for (size_t i = 0; i < positions.size(); ++i)
            if (!std::isfinite(positions[i].x + positions[i].y + positions[i].z)) {
                throwValue("vertices", "non-finite coordinate at vertex " + std::to_string(i));
            }
    }
    py::gil_scoped_release noGil;
    return engine::meshFromArrays(std::move(positions), std::move(indices));
}

engine::Scene volumeFromNumpy(py::handle arrayObj, std::array<float, 3> spacing, std::array<float, 3> origin,
                              const std::string& order) {
    if (order != "zyx" && order != "xyz") throwValue("order", "expected 'zyx' (C order) or 'xyz', got '" + order + "'");
    py::array a = asArray(arrayObj, "volume");
    if (a.ndim() != 3) throwValue("volume", "expected a 3D array, got shape " + shapeText(a));
    const std::string kind = py::str(a.dtype().attr("kind")).cast<std::string>();
    std::string type;
    switch (scalarOf(a)) {
        case Scalar::U8:
            type = "u8";
            break;
        case Scalar::U16:
            type = "u16";
            break;
        case Scalar::I16:
            type = "i16";
            break;
        case Scalar::F32:
            type = "f32";
            break;
        default:
            // Other real types (float64, int32 ...): one converted float32 copy.
            if (kind != "f" && kind != "i" && kind != "u")
                throwValue("volume", "dtype " + dtypeName(a) + " is not a real number type");
            a = a.attr("astype")("float32").cast<py::array>();
            type = "f32";
    }
    engine::VolumeView view;
    view.data = a.data();
    view.type = type;
    for (int ax = 0; ax < 3; ++ax) {
        const int d = order == "zyx" ? 2 - ax : ax;  // array dimension holding axis ax (x, y, z)
        if (a.shape(d) > 1 << 30) throwValue("volume", "dimension too large");
        view.dims[size_t(ax)] = int(a.shape(d));
        view.strides[size_t(ax)] = a.strides(d);
    }
    view.spacing = Vec3f(spacing[0], spacing[1], spacing[2]);
    view.origin = Vec3f(origin[0], origin[1], origin[2]);
    py::gil_scoped_release noGil;
    return engine::volumeFromView(view, "volume");
}

}  // namespace rtfact::python
