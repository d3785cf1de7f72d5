// The extension module rtfact._rtfact: scenes from files or numpy arrays, cameras,
// transfer functions, render -> numpy, image helpers. rtfact/__init__.py re-exports it
// with the Image type (Jupyter display). The GIL is released while the engine loads,
// builds and renders; progress bars are off unless progress=True.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdio>

#include "engine/render_session.h"
#include "engine/scene.h"
#include "python/array_input.h"
#include "python/errors.h"
#include "python/image_output.h"
#include "python/scene_info.h"
#include "python/settings_kwargs.h"

namespace py = pybind11;
using namespace rtfact;
using namespace rtfact::python;

namespace {

py::tuple tupleOf(const Vec3f& v) { return py::make_tuple(v.x, v.y, v.z); }

std::string reprOf(const Vec3f& v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%g, %g, %g)", double(v.x), double(v.y), double(v.z));
    return buf;
}

py::tuple boundsOf(const engine::Scene& s) {
    const AABB b = s.bounds();
    return py::make_tuple(tupleOf(b.lo), tupleOf(b.hi));
}

// The scene's info() with the exact bounds (the text form is rounded).
py::dict sceneInfo(const engine::Scene& s) {
    py::dict d = infoDict(s.info().entries());
    d["bounds"] = boundsOf(s);
    return d;
}

engine::Scene loadScene(py::handle path, const py::kwargs& kw) {
    std::vector<std::string> files;
    auto fspath = [](py::handle p) { return py::module_::import("os").attr("fspath")(p).cast<std::string>(); };
    if (py::isinstance<py::str>(path) || py::hasattr(path, "__fspath__"))
        files.push_back(fspath(path));
    else
        for (py::handle p : path.cast<py::sequence>()) files.push_back(fspath(p));
    const engine::OpenOptions opt = openOptions(kw);
    py::gil_scoped_release noGil;
    return engine::open(files, opt);
}

py::object render(const engine::Scene& scene, const std::optional<CameraFrame>& camera, py::kwargs kw) {
    bool withStats = false;
    if (kw.contains("stats")) {
        withStats = py::bool_(kw["stats"]);
        PyDict_DelItemString(kw.ptr(), "stats");
    }
    const RenderRequest r = renderRequest(scene.kind(), kw);
    const bool cameraArgs = kw.contains("eye") || kw.contains("at") || kw.contains("up") || kw.contains("fov");
    const CameraFrame cam = requestCamera(scene, r, camera, cameraArgs);
    engine::Stats stats = scene.loadStats();
    engine::Frame frame;
    {
        py::gil_scoped_release noGil;
        frame = engine::renderToImage(scene, r.settings, r.frame, cam, r.spp, stats);
    }
    py::array_t<float> image = frameToNumpy(std::move(frame));
    if (!withStats) return image;
    return py::make_tuple(image, infoDict(stats.entries()));
}

}  // namespace

PYBIND11_MODULE(_rtfact, m) {
    m.doc() = "RTfact's engine: CPU ray tracing of point clouds, meshes and volumes (see the rtfact package)";
    registerErrors(m);

    py::class_<CameraFrame>(m, "Camera", "A pinhole camera: eye, target, up vector, vertical field of view (degrees).")
        .def(py::init([](py::handle eye, py::handle at, py::handle up, float fov) {
                 if (!(fov >= 1.0f && fov <= 179.0f)) throwValue("fov", "must be in [1, 179] degrees");
                 CameraFrame f{vec3Arg(eye, "eye"), vec3Arg(at, "at"), vec3Arg(up, "up"), fov};
                 if (!(length(f.at - f.eye) > 0.0f)) throwValue("eye", "coincides with at");
                 if (!(length(cross(normalize(f.at - f.eye), normalize(f.up))) > 1e-3f))
                     throwValue("up", "is parallel to the viewing direction");
                 return f;
             }),
             py::arg("eye"), py::arg("at"), py::arg("up") = py::make_tuple(0, 1, 0), py::arg("fov") = 45.0f)
        .def_property_readonly("eye", [](const CameraFrame& f) { return tupleOf(f.eye); })
        .def_property_readonly("at", [](const CameraFrame& f) { return tupleOf(f.at); })
        .def_property_readonly("up", [](const CameraFrame& f) { return tupleOf(f.up); })
        .def_property_readonly("fov", [](const CameraFrame& f) { return f.fovDeg; })
        .def("__repr__", [](const CameraFrame& f) {
            return "rtfact.Camera(eye=" + reprOf(f.eye) + ", at=" + reprOf(f.at) + ", up=" + reprOf(f.up) +
                   ", fov=" + py::repr(py::float_(f.fovDeg)).cast<std::string>() + ")";
        });

    py::class_<volume::TransferFunction>(m, "TransferFunction",
                                         "A volume transfer function (colour and opacity over the data value).")
        .def_property_readonly("name", [](const volume::TransferFunction& t) { return t.name; })
        .def_property_readonly("colors",
                               [](const volume::TransferFunction& t) {
                                   py::list l;
                                   for (const auto& c : t.colors)
                                       l.append(py::make_tuple(c.x, c.rgb.x, c.rgb.y, c.rgb.z));
                                   return l;
                               })
        .def_property_readonly("opacity",
                               [](const volume::TransferFunction& t) {
                                   py::list l;
                                   for (const auto& o : t.opacity) l.append(py::make_tuple(o.x, o.a));
                                   return l;
                               })
        .def("__repr__", [](const volume::TransferFunction& t) {
            return "rtfact.TransferFunction('" + t.name + "', " + std::to_string(t.colors.size()) + " colours, " +
                   std::to_string(t.opacity.size()) + " opacity points)";
        });
    m.def("transfer_function", &transferFunctionFrom, py::arg("spec"),
          "A transfer function from a preset name, a .json file (ours or a ParaView preset), a dict in either JSON "
          "form, or a list of (x, r, g, b, a) rows (x in 0..1 over the window, sRGB colour and opacity in 0..1).");
    m.attr("presets") = volume::transferFunctionPresets();

    py::class_<engine::Scene>(m, "Scene", "A point cloud, mesh or volume ready to render (rtfact.load/points/...).")
        .def_property_readonly("kind", [](const engine::Scene& s) { return std::string(engine::kindName(s.kind())); })
        .def_property_readonly("bounds", &boundsOf)
        .def_property_readonly("source", &engine::Scene::source)
        .def_property_readonly("warnings", &engine::Scene::warnings)
        .def("info", &sceneInfo,
             "What the scene holds: kind, counts, bounds, value range, default transfer function ...")
        .def(
            "fit_camera",
            [](const engine::Scene& s, py::kwargs kw) {
                const RenderRequest r = renderRequest(s.kind(), kw);
                return requestCamera(s, r, std::nullopt, true);
            },
            "The default camera (as the CLI's): fov=45, size=(w, h) for the aspect; eye/at/up override it and "
            "volume clip= changes the box it fits.")
        .def("__repr__", [](const engine::Scene& s) {
            const AABB b = s.bounds();
            return std::string("<rtfact.Scene ") + engine::kindName(s.kind()) +
                   (s.source().empty() ? "" : " from " + s.source()) + " bounds " + reprOf(b.lo) + " - " +
                   reprOf(b.hi) + ">";
        });

    m.def("load", &loadScene, py::arg("path"),
          "Opens a point cloud, mesh (a list of paths: merged) or volume file that `rtfact` reads. Options: "
          "kind='points'|'mesh'|'volume', dims=(x, y, z), type='u8'|'u16'|'i16'|'f32', endian, spacing, "
          "header_skip, grid (raw and OpenVDB), progress=False.");
    m.def(
        "points",
        [](py::handle xyz, py::handle colors, py::handle normals, py::handle radius, py::handle intensity) {
            return pointsFromNumpy(xyz, colors, normals, radius, intensity);
        },
        py::arg("xyz"), py::arg("colors") = py::none(), py::arg("normals") = py::none(), py::arg("radius") = py::none(),
        py::arg("intensity") = py::none(),
        "A point cloud from N x 3 float32/float64 positions; colors N x 3 uint8 or float 0..1; normals N x 3; "
        "radius a number or N values; intensity N values.");
    m.def("mesh", &meshFromNumpy, py::arg("vertices"), py::arg("faces"),
          "A triangle mesh from V x 3 float vertices and F x 3 integer faces.");
    m.def("volume", &volumeFromNumpy, py::arg("array"), py::arg("spacing") = std::array<float, 3>{1, 1, 1},
          py::arg("origin") = std::array<float, 3>{0, 0, 0}, py::arg("order") = "zyx",
          "A volume from a 3D uint8/uint16/int16/float32 array indexed [z, y, x] (order='zyx') or [x, y, z] "
          "(order='xyz'), read in place in any memory layout; spacing and origin as (x, y, z).");
    m.def("spheres", &engine::spheres, py::arg("count") = 16, "The analytic demo scene (`rtfact spheres`).");
    m.def("render", &render, py::arg("scene"), py::arg("camera") = py::none(),
          "Renders a scene into an (h, w, 4) float32 linear RGBA array; settings are named like the CLI options");
    m.def(
        "info",
        [](py::handle x) {
            if (py::isinstance<engine::Scene>(x)) return sceneInfo(x.cast<engine::Scene>());
            const std::string path = py::module_::import("os").attr("fspath")(x).cast<std::string>();
            std::vector<std::pair<std::string, std::string>> entries;
            {
                py::gil_scoped_release noGil;
                entries = engine::fileInfo(path);
            }
            return infoDict(entries);
        },
        py::arg("scene_or_path"), "What a scene or a file holds (`rtfact info FILE`), as a dict.");
    m.def("to_srgb8", &toSrgb8, py::arg("image"), "(h, w, 3) uint8 sRGB of a linear float image.");
    m.def("save_image", &saveImage, py::arg("path"), py::arg("image"),
          "Writes a linear float image; the format follows the extension (.png .exr .tif .jpg).");
    m.def("read_image", &readImage, py::arg("path"), "Reads an image file as (h, w, 4) float32 linear RGBA.");
    m.def("_png_bytes", &pngBytes, py::arg("image"));
}
