// rtfact-bench volume FILE: RTfact's packet DVR against two peers on the same volume,
// transfer function, view, step size (in voxels) and thread count, in one process:
// VTK's vtkFixedPointVolumeRayCastMapper (bench_vtk_volume.h; on a private Xvfb when there
// is no DISPLAY) and OpenVDB's ray marcher. Image quality: PSNR of each frame against
// RTfact at a fine step (--ref-step) with the same transfer function. The OpenVDB peer
// is the primary-ray part of openvdb::tools::VolumeRender: a VolumeRayIntersector
// (hierarchical DDA over the active tree, `hits` spans) and a BoxSampler (trilinear) per
// sample, sampling at t = step * k like VolumeRender, with
// the same TF lookup table and early termination; no shadow rays on either side. Its
// grid's active voxels are those the TF makes visible (the information our macrocells
// get), or the file's own tree for .vdb input. In --mode iso the OpenVDB peer is its
// level-set ray caster instead (VdbIsoCaster), and VTK, whose CPU ray caster has no
// isosurface blend, is left out.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <openvdb/tools/RayIntersector.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <thread>

#include "bench/bench_commands.h"
#include "bench/bench_common.h"
#include "bench/bench_vtk_volume.h"
#include "core/render/framebuffer.h"
#include "core/render/image_io.h"
#include "core/render/pinhole_camera.h"
#include "core/render/pixel_center_sampler.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/render/srgb.h"
#include "core/render/tile_scheduler.h"
#include "core/simd/native.h"
#include "core/util/error.h"
#include "engine/built_scene.h"
#include "engine/render_session.h"
#include "volume/transfer_function.h"
#include "volume/volume_integrator.h"
#include "volume/volume_io.h"
#include "volume/volume_scene.h"

namespace rtfact::bench {
namespace {

using namespace rtfact::volume;

// For each pixel of rows [y0, y1): its primary ray (origin, direction) and its RGBA in rgba,
// cleared to transparent black; the OpenVDB peers render pixel by pixel through this.
template <class F>
void forEachPixelRay(const PinholeCamera& cam, int y0, int y1, std::vector<float>& rgba, F&& shade) {
    const int w = cam.width();
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < w; ++x) {
            RayPacket<1> r;
            cam.generate<1>(Packet<1>(float(x) + 0.5f), Packet<1>(float(y) + 0.5f), r);
            float* px = &rgba[(size_t(y) * size_t(w) + size_t(x)) * 4];
            px[0] = px[1] = px[2] = px[3] = 0;
            shade(r.org.lane(0), r.dir.lane(0), px);
        }
}

// The peer: OpenVDB intersector + BoxSampler, front-to-back with our TF table.
struct VdbMarcher {
    openvdb::FloatGrid::Ptr grid;
    const TFTable* tf;
    float tfMul, tfAdd, step, term;

    // Renders rows [y0, y1) into rgba; returns samples taken.
    uint64_t rows(const PinholeCamera& cam, int y0, int y1, std::vector<float>& rgba,
                  openvdb::tools::VolumeRayIntersector<openvdb::FloatGrid>& inter) const {
        using RayT = openvdb::math::Ray<double>;
        auto acc = grid->getConstAccessor();
        openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
            acc, grid->transform());
        std::vector<RayT::TimeSpan> spans;
        uint64_t samples = 0;
        forEachPixelRay(cam, y0, y1, rgba, [&](const Vec3f& o, const Vec3f& d, float* px) {
            RayT ray(openvdb::Vec3d(o.x, o.y, o.z), openvdb::Vec3d(d.x, d.y, d.z));
            if (!inter.setWorldRay(ray)) return;
            inter.hits(spans);
            float cr = 0, cg = 0, cb = 0, a = 0;
            for (const auto& sp : spans) {
                for (double t = step * std::ceil(sp.t0 / step); t <= sp.t1 && a < term; t += step) {
                    const float v = sampler.isSample(inter.getIndexPos(t));
                    ++samples;
                    const int i = int(std::clamp(v * tfMul + tfAdd, 0.0f, float(tf->size - 1)));
                    const float sa = tf->a[size_t(i)];
                    if (sa <= 0) continue;
                    const float wgt = (1 - a) * sa;
                    cr += wgt * tf->r[size_t(i)];
                    cg += wgt * tf->g[size_t(i)];
                    cb += wgt * tf->b[size_t(i)];
                    a += wgt;
                }
                if (a >= term) break;
            }
            px[0] = cr;
            px[1] = cg;
            px[2] = cb;
            px[3] = a;
        });
        return samples;
    }
};

// The isosurface peer: OpenVDB's level-set ray caster (LevelSetRayIntersector, the primary
// rays of tools::LevelSetRayTracer: hierarchical DDA over the narrow band, the crossing by
// linear interpolation) on a level set of the volume at the isovalue (tools::levelSetRebuild),
// shaded as VolumeIntegrator's iso mode: the TF colour at the isovalue times the headlight
// term of the surface normal.
// Rays are clipped to the volume's box, as ours are: where the box cuts the surface (the
// bonsai's pot), the level set closes it outside the box and a ray entering inside the
// object finds the surface where it leaves, as our march does (else that cap alone cost the
// peer 14 dB against the reference).
struct VdbIsoCaster {
    using Intersector = openvdb::tools::LevelSetRayIntersector<openvdb::FloatGrid>;
    openvdb::FloatGrid::Ptr levelSet;
    Vec3f color;
    Vec3f boxLo, boxHi;  // world space

    // Renders rows [y0, y1) into rgba; returns the rays that hit.
    uint64_t rows(const PinholeCamera& cam, int y0, int y1, std::vector<float>& rgba, const Intersector& inter) const {
        uint64_t hits = 0;
        forEachPixelRay(cam, y0, y1, rgba, [&](const Vec3f& o, const Vec3f& d, float* px) {
            double t0 = 0, t1 = 1e30;
            for (int a = 0; a < 3; ++a) {
                const double inv = 1.0 / double(d[a]);  // +-inf along a slab: the other axes decide
                const double ta = (double(boxLo[a]) - o[a]) * inv, tb = (double(boxHi[a]) - o[a]) * inv;
                t0 = std::max(t0, std::min(ta, tb));
                t1 = std::min(t1, std::max(ta, tb));
            }
            if (!(t0 < t1)) return;
            const openvdb::math::Ray<double> ray(openvdb::Vec3d(o.x, o.y, o.z), openvdb::Vec3d(d.x, d.y, d.z), t0, t1);
            openvdb::Vec3d xyz, n;
            if (!inter.intersectsWS(ray, xyz, n)) return;
            ++hits;
            // VolumeIntegrator::shadeFactor: 0.2 + 0.8 c + 0.25 c^20, c = |n.d| / |n|
            const double n2 = n.lengthSqr();
            double shade = 1.0;
            if (n2 > 1e-12) {
                const double c = std::fabs(n.dot(ray.dir())) / std::sqrt(n2);
                shade = 0.2 + 0.8 * c + 0.25 * std::pow(c, 20.0);
            }
            px[0] = float(color.x * shade);
            px[1] = float(color.y * shade);
            px[2] = float(color.z * shade);
            px[3] = 1.0f;
        });
        return hits;
    }
};

// The level set of v's stored values at isoStored: isoStored - stored is negative inside (above
// the isovalue), as a level set's interior; outside the volume it is positive (the grid's
// background, above every voxel's value so that every voxel stays active), so a surface the
// volume's box cuts is closed there.
openvdb::FloatGrid::Ptr isoLevelSet(const BrickedVolume& v, float isoStored, const openvdb::math::Transform& xf) {
    using Dense = openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ>;  // x fastest, as our index
    Dense dense(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(v.dims[0] - 1, v.dims[1] - 1, v.dims[2] - 1)));
    float* out = dense.data();
    tbb::parallel_for(0, v.dims[2], [&](int k) {
        for (int j = 0; j < v.dims[1]; ++j)
            for (int i = 0; i < v.dims[0]; ++i)
                out[(size_t(k) * size_t(v.dims[1]) + size_t(j)) * size_t(v.dims[0]) + size_t(i)] =
                    isoStored - v.stored(i, j, k);
    });
    const float top = *std::max_element(out, out + v.voxelCount());
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(std::max(top, 0.0f) + 1.0f);
    openvdb::tools::copyFromDense(dense, *grid, 0.0f);
    grid->setTransform(xf.copy());
    openvdb::FloatGrid::Ptr ls = openvdb::tools::levelSetRebuild(*grid, 0.0f);
    ls->setGridClass(openvdb::GRID_LEVEL_SET);
    return ls;
}

openvdb::FloatGrid::Ptr toVdb(const BrickedVolume& v, const TFTable& tf) {
    // Stored values; active where the TF makes the voxel visible.
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
    auto acc = grid->getAccessor();
    for (int k = 0; k < v.dims[2]; ++k)
        for (int j = 0; j < v.dims[1]; ++j)
            for (int i = 0; i < v.dims[0]; ++i) {
                const float stored = v.stored(i, j, k);
                if (tf.a[size_t(tf.index(stored * v.scale + v.offset))] > 0)
                    acc.setValue(openvdb::Coord(i, j, k), stored);
            }
    return grid;
}

// PSNR of RGB over black against `ref` (peak 1), in linear values: both renderers
// composite linear colours, and VTK's 8-bit read-back stays exact enough there
// (quantisation alone caps it at 59 dB).
double psnr(const std::vector<float>& img, const std::vector<float>& ref) {
    double se = 0;
    for (size_t p = 0; p < ref.size(); p += 4)
        for (size_t c = 0; c < 3; ++c) {
            const double d = double(std::clamp(img[p + c], 0.0f, 1.0f)) - double(std::clamp(ref[p + c], 0.0f, 1.0f));
            se += d * d;
        }
    const double mse = se / (double(ref.size() / 4) * 3.0);
    return mse <= 0 ? 99.0 : -10.0 * std::log10(mse);
}

// The same in 8-bit sRGB (what the tests' image metric and the PNG files use).
double psnrSrgb8(const std::vector<float>& img, const std::vector<float>& ref) {
    double se = 0;
    for (size_t p = 0; p < ref.size(); p += 4)
        for (size_t c = 0; c < 3; ++c) {
            const double d = double(linearToSrgb8(img[p + c])) - double(linearToSrgb8(ref[p + c]));
            se += d * d;
        }
    const double mse = se / (double(ref.size() / 4) * 3.0);
    return mse <= 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

double nonBlackFraction(const std::vector<float>& img) {
    size_t n = 0;
    for (size_t p = 0; p < img.size(); p += 4) n += img[p] > 0 || img[p + 1] > 0 || img[p + 2] > 0;
    return double(n) / double(img.size() / 4);
}

}  // namespace

int benchVolume(int argc, char** argv) {
    CLI::App app{
        "rtfact-bench volume: RTfact DVR vs VTK's vtkFixedPointVolumeRayCastMapper and OpenVDB's ray marcher "
        "(VolumeRayIntersector + BoxSampler)"};
    std::string file, dims, type, tfName = "ct-bone", size = "1024x1024", eye, at, up, outPrefix, mode = "dvr";
    float step = 0.5f, fov = 45.0f, refStep = 0.1f;
    int threads = 0, frames = 3, packet = 64;
    std::optional<float> window, level;
    bool skipPeer = false, skipVtk = false, everyStep = false, preintegrated = false;
    app.add_option("FILE", file, "Volume file")->required();
    app.add_option("--dims", dims, "Raw dims X,Y,Z");
    app.add_option("--type", type, "Raw type u8|u16|i16|f32");
    app.add_option("--tf", tfName, "Transfer function preset or .json")->capture_default_str();
    app.add_option("--window", window, "Window width");
    app.add_option("--level", level, "Window level");
    app.add_option("--step", step, "Step in voxels")->capture_default_str()->check(CLI::PositiveNumber);
    app.add_option("--mode", mode,
                   "dvr, shaded (VTK shades too), mip (VTK's maximum intensity blend; OpenVDB left out) or iso "
                   "(OpenVDB's level-set ray caster; VTK's CPU caster has no isosurface blend)")
        ->capture_default_str()
        ->check(CLI::IsMember({"dvr", "shaded", "mip", "iso"}));
    std::optional<float> iso;
    app.add_option("--iso", iso, "Isovalue for --mode iso, data units (default: as rtfact volume)");
    app.add_option("--ref-step", refStep, "Step of the RTfact reference for PSNR (0: no reference)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    app.add_option("--size", size, "Image WxH")->capture_default_str();
    app.add_option("--eye", eye, "Camera eye x,y,z");
    app.add_option("--at", at, "Camera target x,y,z");
    app.add_option("--up", up, "Camera up x,y,z");
    app.add_option("--fov", fov, "Vertical FOV")->capture_default_str();
    app.add_option("--threads", threads, "All-threads run count (0: all cores); a 1-thread run is always made")
        ->capture_default_str();
    app.add_option("--frames", frames, "Frames per measurement (best is reported)")->capture_default_str();
    app.add_option("--packet", packet, "RTfact packet size")->capture_default_str();
    app.add_option(
        "--images", outPrefix,
        "Write PREFIX_rtfact.png, PREFIX_vtk.png (and _vtk_cast.png), PREFIX_openvdb.png and PREFIX_reference.png");
    app.add_flag("--no-peer", skipPeer, "Only RTfact (no VTK, no OpenVDB)");
    app.add_flag("--no-vtk", skipVtk, "Leave out the VTK peer (it needs an X server: Xvfb without DISPLAY)");
    app.add_flag("--no-adaptive-steps", everyStep,
                 "RTfact marches every step in low-opacity bricks too (no 2x/4x steps), as rtfact volume "
                 "--no-adaptive-steps: its per-sample rate");
    app.add_flag("--preintegrated", preintegrated,
                 "RTfact composites pre-integrated segments between samples, as rtfact volume --preintegrated");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return usageExit(app, e);
    }
    const bool isoMode = mode == "iso";
    const bool runVtk = !skipPeer && !skipVtk && !isoMode, runVdb = !skipPeer && (mode == "dvr" || isoMode);
    // VTK's render window needs X: without DISPLAY, a private Xvfb for this run.
    std::optional<VirtualDisplay> display;
    if (runVtk) display.emplace(argc, argv);
    if (!outPrefix.empty()) checkImageWritable(outPrefix + "_rtfact.png");  // fail before rendering
    int w = 0, h = 0;
    if (std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1) throw Error("--size", "expected WxH");
    // Loading, the default view, the TF and window and the volume scene are the engine's,
    // as for `rtfact volume`; the peer gets the same bricks, TF table and camera.
    engine::OpenOptions oo;
    oo.kind = engine::SceneKind::Volume;
    oo.progress = false;
    if (!dims.empty()) oo.volume.dims = parseDims(dims);
    oo.volume.type = type;
    oo.volume.progress = false;
    const bool isVdb = dims.empty() && file.size() > 4 && file.substr(file.size() - 4) == ".vdb";
    auto t0 = Clock::now();
    engine::Scene sc = engine::open({file}, oo);
    const double loadMs = msSince(t0);
    {
        const Vec3f sp = engine::builtVolume(sc, {}).volume->spacing;
        if (std::fabs(sp.x - sp.y) > 1e-6f || std::fabs(sp.x - sp.z) > 1e-6f) {
            std::printf(
                "note: anisotropic spacing; both renderers use isotropic spacing %g here (OpenVDB's intersector "
                "needs uniform voxels)\n",
                double(minComponent(sp)));
            oo.volume.spacing = Vec3f(minComponent(sp));
            sc = engine::open({file}, oo);
        }
    }
    engine::Settings settings;
    settings.volume.tf = resolveTransferFunction(tfName);
    settings.volume.window = window;
    settings.volume.level = level;
    settings.volume.step = step;
    settings.volume.mode = mode;
    settings.volume.adaptiveSteps = !everyStep;
    settings.volume.preintegrated = preintegrated;
    settings.volume.iso = iso;
    t0 = Clock::now();
    const engine::BuiltVolume built = engine::builtVolume(sc, settings);
    const double buildMs = msSince(t0);
    const BrickedVolume& vol = *built.volume;
    const TFTable& table = built.setup.table;
    const auto win = built.setup.window;
    CameraFrame frame = engine::fitCamera(sc.defaultView(settings), fov, float(w) / float(h));
    if (!eye.empty()) frame.eye = parseVec(eye, "--eye");
    if (!at.empty()) frame.at = parseVec(at, "--at");
    if (!up.empty()) frame.up = parseVec(up, "--up");
    const PinholeCamera cam(frame, w, h);
    const int allThreads = resolveThreads(threads);
    std::printf("volume %s: %dx%dx%d %s (%s), %zu of %zu bricks stored, %.1f MB, load %.0f ms, TF %.0f ms\n",
                file.c_str(), vol.dims[0], vol.dims[1], vol.dims[2], storageName(vol.storage), vol.sourceType.c_str(),
                vol.storedBricks(), vol.brickCount(), double(vol.memoryBytes()) / 1048576.0, loadMs, buildMs);
    std::printf("view %dx%d, %s, tf %s window [%g, %g], step %g voxels%s, packet %d, frames %d (best reported)\n", w, h,
                mode.c_str(), built.setup.tf.name.c_str(), double(win.first), double(win.second), double(step),
                everyStep ? " (every step: no adaptive steps)" : "", packet, frames);
    std::printf("cpu: %s, isa %s\n", cpuModel().c_str(), simd::isaName());
    if (!skipPeer && !runVdb)
        std::printf("note: the OpenVDB peer marches DVR only; left out in --mode %s\n", mode.c_str());
    if (!skipPeer && isoMode)
        std::printf(
            "note: VTK's vtkFixedPointVolumeRayCastMapper has no isosurface blend (GPU mappers only); left out; "
            "OpenVDB = its level-set ray caster, isovalue %g\n",
            double(built.setup.render.iso));

    struct Result {
        double ms = 0;
        uint64_t samples = 0;
    };
    std::vector<float> ourImage;
    auto runOurs = [&](int th) {
        // One 1-sample pass per frame: the session's first sample is the pixel centre.
        engine::FrameOptions fo;
        fo.width = w;
        fo.height = h;
        fo.packet = packet;
        fo.threads = th;
        engine::RenderSession session(sc, settings, fo, frame);
        Result best{1e300, 0};
        // RTFACT_BENCH_CLOCK=cpu: one thread's figure is its CPU time (the one-thread tile
        // arena runs in this thread).
        const bool cpu = th == 1 && cpuClockForOneThread();
        for (int f = 0; f < frames; ++f) {
            session.setCamera(frame);  // restarts the accumulation
            const double c0 = cpu ? threadCpuMs() : 0.0;
            const engine::PassResult pr = session.renderPass();
            const double ms = cpu ? threadCpuMs() - c0 : pr.render.ms;
            if (ms < best.ms) best = {ms, pr.render.counters.volumeSamples};
            if (f == 0) ourImage = session.frame().rgba;
        }
        return best;
    };

    openvdb::initialize();
    VdbMarcher peer;
    VdbIsoCaster isoPeer;
    std::vector<float> peerImage(size_t(w) * size_t(h) * 4);
    auto runPeer = [&](int th) {
        Result best{1e300, 0};
        // Rows of 4 in parallel, each task with its own copy of the intersector (not
        // thread-safe); in iso mode `samples` are the rays that hit (the caster's steps are its own).
        auto time = [&](const auto& renderer, const auto& master) {
            for (int f = 0; f < frames; ++f) {
                std::atomic<uint64_t> samples{0};
                const double ms = timeArena(th, [&] {
                    tbb::parallel_for(tbb::blocked_range<int>(0, h, 4), [&](const tbb::blocked_range<int>& r) {
                        auto inter = master;
                        samples += renderer.rows(cam, r.begin(), r.end(), peerImage, inter);
                    });
                });
                if (ms < best.ms) best = {ms, samples.load()};
            }
        };
        if (isoMode)
            time(isoPeer, VdbIsoCaster::Intersector(*isoPeer.levelSet));
        else
            time(peer, openvdb::tools::VolumeRayIntersector<openvdb::FloatGrid>(*peer.grid));
        return best;
    };

    if (runVdb && isoMode) {
        t0 = Clock::now();
        openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(double(vol.spacing.x));
        xf->postTranslate(openvdb::Vec3d(vol.origin.x, vol.origin.y, vol.origin.z));
        const float isoStored = (built.setup.render.iso - vol.offset) / vol.scale;
        isoPeer.levelSet = isoLevelSet(vol, isoStored, *xf);
        if (isoPeer.levelSet->empty()) {
            const auto [lo, hi] = vol.valueRange();
            char msg[160];
            std::snprintf(msg, sizeof msg, "no isosurface at isovalue %g (values lie in [%g, %g]): nothing to compare",
                          double(built.setup.render.iso), double(lo), double(hi));
            throw Error(file, msg);
        }
        const size_t i = size_t(table.index(built.setup.render.iso));
        isoPeer.color = Vec3f(table.r[i], table.g[i], table.b[i]);
        isoPeer.boxLo = vol.origin;
        isoPeer.boxHi =
            vol.origin + Vec3f(float(vol.dims[0] - 1), float(vol.dims[1] - 1), float(vol.dims[2] - 1)) * vol.spacing;
        std::printf("openvdb level set: %llu active voxels, built in %.0f ms\n",
                    (unsigned long long)isoPeer.levelSet->activeVoxelCount(), msSince(t0));
    } else if (runVdb) {
        t0 = Clock::now();
        if (isVdb) {
            // The file's own sparse tree (values in data units = stored units here).
            openvdb::io::File f(file);
            f.open();
            for (auto it = f.beginName(); it != f.endName(); ++it) {
                auto base = f.readGrid(it.gridName());
                if ((peer.grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base))) break;
            }
            f.close();
        } else {
            peer.grid = toVdb(vol, table);
        }
        if (!peer.grid) throw Error(file, "no float grid for the OpenVDB peer");
        openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(double(vol.spacing.x));
        // Our grid starts at the active bbox minimum; align the VDB index space with ours.
        openvdb::Coord bmin(0, 0, 0);
        if (isVdb) bmin = peer.grid->evalActiveVoxelBoundingBox().min();
        xf->postTranslate(openvdb::Vec3d(vol.origin.x, vol.origin.y, vol.origin.z) -
                          openvdb::Vec3d(bmin.x(), bmin.y(), bmin.z()) * double(vol.spacing.x));
        peer.grid->setTransform(xf);
        peer.tf = &table;
        const float k = float(table.size - 1) / (table.hi - table.lo);
        peer.tfMul = vol.scale * k;
        peer.tfAdd = (vol.offset - table.lo) * k + 0.5f;
        peer.step = step;
        peer.term = built.setup.render.earlyTermination;
        std::printf("openvdb grid: %llu active voxels, built in %.0f ms\n",
                    (unsigned long long)peer.grid->activeVoxelCount(), msSince(t0));
    }
    std::unique_ptr<VtkVolumePeer> vtk;
    if (runVtk) {
        t0 = Clock::now();
        VtkVolumeView view;
        view.volume = &vol;
        view.tf = built.setup.tf;
        view.window = {table.lo, table.hi};
        view.stepVoxels = step;
        view.shaded = mode == "shaded";
        view.mip = mode == "mip";
        view.camera = frame;
        view.width = w;
        view.height = h;
        vtk = std::make_unique<VtkVolumePeer>(view);
        std::printf(
            "vtk: vtkFixedPointVolumeRayCastMapper (VTK 9.1), sample distance %g world units, set up in %.0f ms; "
            "vtk ms = its ray cast, Render() = the whole window render\n",
            double(step * minComponent(vol.spacing)), msSince(t0));
    }

    std::printf("%-8s %7s %10s %9s %11s %12s\n", "who", "threads", "ms/frame", "Mrays/s", "Msamples/s", "samples");
    const double rays = double(w) * double(h);
    std::string summary;
    char line[256];
    for (int th : {1, allThreads}) {
        const Result ours = runOurs(th);
        std::printf("%-8s %7d %10.1f %9.2f %11.1f %12llu\n", "rtfact", th, ours.ms, rays / (ours.ms * 1e3),
                    double(ours.samples) / (ours.ms * 1e3), (unsigned long long)ours.samples);
        std::snprintf(line, sizeof line, "threads=%d rtfact_ms=%.1f", th, ours.ms);
        summary += line;
        if (vtk) {
            const VtkVolumePeer::Timing t = vtk->render(th, frames);
            std::printf("%-8s %7d %10.1f %9.2f %11s %12s  Render() %.1f ms%s\n", "vtk", th, t.castMs,
                        rays / (t.castMs * 1e3), "-", "-", t.renderMs,
                        th == 1 && cpuClockForOneThread() ? " (wall time: the ratio mixes clocks)" : "");
            std::printf("ratio    %7d %10.2fx (vtk ms / rtfact ms)\n", th, t.castMs / ours.ms);
            std::snprintf(line, sizeof line, " vtk_ms=%.1f vtk/rtfact=%.2fx", t.castMs, t.castMs / ours.ms);
            summary += line;
        }
        if (runVdb) {
            const Result theirs = runPeer(th);
            if (isoMode)  // the level-set caster's steps are not samples; its hits instead
                std::printf("%-8s %7d %10.1f %9.2f %11s %12s  %llu rays hit\n", "openvdb", th, theirs.ms,
                            rays / (theirs.ms * 1e3), "-", "-", (unsigned long long)theirs.samples);
            else
                std::printf("%-8s %7d %10.1f %9.2f %11.1f %12llu\n", "openvdb", th, theirs.ms, rays / (theirs.ms * 1e3),
                            double(theirs.samples) / (theirs.ms * 1e3), (unsigned long long)theirs.samples);
            std::printf("ratio    %7d %10.2fx (openvdb ms / rtfact ms)\n", th, theirs.ms / ours.ms);
            std::snprintf(line, sizeof line, " openvdb_ms=%.1f openvdb/rtfact=%.2fx", theirs.ms, theirs.ms / ours.ms);
            summary += line;
        }
        summary += "\n";
        if (th == allThreads) break;
    }
    std::printf("summary (%s, %s):\n%s", cpuModel().c_str(), simd::isaName(), summary.c_str());
    if (runVdb) {
        double diff = 0;
        for (size_t i = 0; i < ourImage.size(); ++i) diff += std::fabs(ourImage[i] - peerImage[i]);
        std::printf("mean |rtfact - openvdb| per channel: %.4f (same view and TF; sample positions differ)\n",
                    diff / double(ourImage.size()));
    }
    std::vector<float> vtkImage, vtkCast, refImage;
    if (vtk) {
        vtkCast = vtk->castImage();
        vtkImage = vtk->image();
    }
    if (refStep > 0) {
        // The fine-step reference: RTfact's plain march (no opacity-adaptive steps), same TF
        // (its opacity corrected for the finer step), same camera, rendered through the
        // volume library directly so that the adaptive steps can be switched off.
        engine::Settings refSettings = settings;
        refSettings.volume.step = refStep;
        const engine::BuiltVolume refBuilt = engine::builtVolume(sc, refSettings);
        VolumeRenderSettings plain = refBuilt.setup.render;
        plain.maxStepMultiple = 1;
        t0 = Clock::now();
        withVolumeScene(vol, refBuilt.setup.table, plain, [&](const auto& scene) {
            RGBAFramebuffer fb(w, h);
            const RayTracingRenderer<PixelCenterSampler, VolumeIntegrator> renderer{};
            RenderOptions ro;
            ro.threads = allThreads;
            ro.progress = false;
            renderImage<64>(renderer, scene, cam, fb, ro);
            refImage = fb.resolved(1);
        });
        std::printf(
            "quality: PSNR of RGB over black (linear, peak 1; 8-bit sRGB in brackets) against RTfact at step %g "
            "voxels (%.0f ms)%s:\n",
            double(refStep), msSince(t0),
            vtk ? "; vtk = its window read back (vtkWindowToImageFilter), vtk_cast = the mapper's own image" : "");
        std::printf("psnr_rtfact_db=%.2f [%.2f]", psnr(ourImage, refImage), psnrSrgb8(ourImage, refImage));
        if (vtk)
            std::printf(" psnr_vtk_db=%.2f [%.2f] psnr_vtk_cast_db=%.2f [%.2f]", psnr(vtkImage, refImage),
                        psnrSrgb8(vtkImage, refImage), psnr(vtkCast, refImage), psnrSrgb8(vtkCast, refImage));
        if (runVdb)
            std::printf(" psnr_openvdb_db=%.2f [%.2f]", psnr(peerImage, refImage), psnrSrgb8(peerImage, refImage));
        std::printf("\n");
    }
    if (vtk)
        std::printf("vtk_nonblack=%.3f rtfact_nonblack=%.3f (fraction of pixels not black)\n",
                    nonBlackFraction(vtkImage), nonBlackFraction(ourImage));
    if (!outPrefix.empty()) {
        writeImage(outPrefix + "_rtfact.png", w, h, ourImage);
        if (runVdb) writeImage(outPrefix + "_openvdb.png", w, h, peerImage);
        if (vtk) writeImage(outPrefix + "_vtk.png", w, h, vtkImage);
        if (vtk) writeImage(outPrefix + "_vtk_cast.png", w, h, vtkCast);
        if (!refImage.empty()) writeImage(outPrefix + "_reference.png", w, h, refImage);
    }
    return 0;
}

}  // namespace rtfact::bench
