// rtfact-bench points FILE: RTfact's LoD disc tracer (full detail and LoD; the LoD
// kd-tree, or with --accel wide the wide BVH of disc blocks) against Embree 3 oriented-disc points
// (RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT) with the same centres, normals (decoded from RTfact's quantised ones) and
// radii, the same camera rays and thread counts, in one process. Embree runs in its best mode for coherent primary
// rays: rtcIntersect16 on 4x4 pixel blocks, coherent context flag, medium build. Both sides do the same per-pixel work:
// ray generation, nearest hit, eyelight shading
// (|cos| x point colour) written to a frame. PSNR of LoD against full detail is on that
// shading, 8-bit.
#include <embree3/rtcore.h>
#include <sys/resource.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <thread>

#include "bench/bench_commands.h"
#include "bench/bench_common.h"
#include "bench/bench_embree.h"
#include "core/render/pinhole_camera.h"
#include "core/render/ray_tracing_renderer.h"
#include "core/util/error.h"
#include "core/util/huge_pages.h"
#include "core/util/progress.h"
#include "engine/built_scene.h"
#include "engine/render_session.h"
#include "points/point_scene.h"

namespace rtfact::bench {
namespace {

using namespace rtfact::points;

struct Frame {
    int w, h;
    std::vector<float> shade;  // eyelight value, 0 for background
    std::vector<uint8_t> hit;
    Frame(int w_, int h_) : w(w_), h(h_), shade(size_t(w_) * size_t(h_)), hit(size_t(w_) * size_t(h_)) {}
};

float luminance(uint32_t rgba) {
    const Vec3f c = unpackRGB(rgba);
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

template <int N>
struct RTfactSide {
    static constexpr int bw = packetBlockWidth(N), bh = N / bw;
    const PointScene& scene;
    const PinholeCamera& cam;
    float subX = 0.5f, subY = 0.5f;  // where in its pixel each ray goes (the supersampled reference)

    void tile(Frame& f, int tx, int ty) const {
        for (int y = ty; y < std::min(ty + kTile, f.h); y += bh)
            for (int x = tx; x < std::min(tx + kTile, f.w); x += bw) {
                Packet<N> px, py;
                blockPixels<N, bw>(x, y, subX, subY, px, py);
                RayPacket<N> rays;
                cam.template generate<N>(px, py, rays);
                const auto hit = scene.template intersect<N>(rays, Mask<N>(true));
                for (int i = 0; i < N; ++i) {
                    const size_t pix = size_t(y + i / bw) * size_t(f.w) + size_t(x + i % bw);
                    const int32_t id = hit.id[i];
                    if (id == -1) {
                        f.shade[pix] = 0.0f;
                        f.hit[pix] = 0;
                        continue;
                    }
                    const Disc d = scene.disc(id);
                    f.shade[pix] = std::fabs(dot(d.n(), rays.dir.lane(i))) * luminance(d.rgba);
                    f.hit[pix] = 1;
                }
            }
    }
};

struct EmbreeSide {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    const std::vector<Disc>& discs;
    const PinholeCamera& cam;

    EmbreeSide(const std::vector<Disc>& d, const PinholeCamera& c, int threads) : discs(d), cam(c) {
        device = newEmbreeDevice(threads);
    }
    ~EmbreeSide() {
        if (scene) rtcReleaseScene(scene);
        rtcReleaseDevice(device);
    }
    // Build ms (filling Embree's buffers excluded); gEmbreeBytes then holds its memory.
    double build() {
        if (scene) rtcReleaseScene(scene);
        gEmbreeBytes = 0;
        scene = rtcNewScene(device);
        rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
        auto* v = static_cast<float*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 16, discs.size()));
        auto* n = static_cast<float*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 12, discs.size()));
        tbb::parallel_for(size_t(0), discs.size(), [&](size_t i) {
            const Disc& d = discs[i];
            const Vec3f nn = d.n();
            v[4 * i] = d.center.x, v[4 * i + 1] = d.center.y, v[4 * i + 2] = d.center.z, v[4 * i + 3] = d.radius;
            n[3 * i] = nn.x, n[3 * i + 1] = nn.y, n[3 * i + 2] = nn.z;
        });
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        const auto t0 = Clock::now();
        rtcCommitScene(scene);
        return msSince(t0);
    }

    void tile(Frame& f, int tx, int ty) const {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        alignas(64) int valid[16];
        std::fill(valid, valid + 16, -1);
        for (int y = ty; y < std::min(ty + kTile, f.h); y += 4)
            for (int x = tx; x < std::min(tx + kTile, f.w); x += 4) {
                Packet<16> px, py;
                blockPixels<16, 4>(x, y, 0.5f, 0.5f, px, py);
                RayPacket<16> rays;
                cam.generate<16>(px, py, rays);
                alignas(64) RTCRayHit16 rh;
                toEmbree(rays, rh);
                rtcIntersect16(valid, scene, &ctx, &rh);
                for (int i = 0; i < 16; ++i) {
                    const size_t pix = size_t(y + i / 4) * size_t(f.w) + size_t(x + i % 4);
                    if (rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
                        f.shade[pix] = 0.0f;
                        f.hit[pix] = 0;
                        continue;
                    }
                    const Disc& d = discs[rh.hit.primID[i]];
                    f.shade[pix] = std::fabs(dot(d.n(), rays.dir.lane(i))) * luminance(d.rgba);
                    f.hit[pix] = 1;
                }
            }
    }
};

// PSNR of the 8-bit shading over the whole image, or (object) over the pixels where either
// frame hits a disc: the background is most of the image and identical in both, so the
// whole-image figure flatters a coarse LoD cut (the dragon at quality 24 is visibly lumpy at
// 31 dB whole-image).
double psnr8(const Frame& a, const Frame& b, bool object = false) {
    double se = 0;
    size_t n = 0;
    for (size_t i = 0; i < a.shade.size(); ++i) {
        if (object && !a.hit[i] && !b.hit[i]) continue;
        const double x = std::lround(std::clamp(a.shade[i], 0.0f, 1.0f) * 255.0f),
                     y = std::lround(std::clamp(b.shade[i], 0.0f, 1.0f) * 255.0f);
        se += (x - y) * (x - y);
        ++n;
    }
    const double mse = n == 0 ? 0.0 : se / double(n);
    return mse == 0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

// Full detail with s x s rays a pixel, averaged: the anti-aliased picture both the 1-ray
// full-detail frame and a LoD frame approximate (a LoD cut averages the normals and colours
// of discs smaller than a pixel, which one ray a pixel samples at random: against the 1-ray
// frame that prefiltering counts as error). A pixel is object where any of its rays hits.
template <int N>
Frame supersampledFullDetail(PointScene& scene, const PinholeCamera& cam, int w, int h, int threads, int s) {
    Frame ref(w, h), f(w, h);
    scene.setLoD(cam.cone(), 0.0f);
    for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) {
            const RTfactSide<N> rt{scene, cam, (float(i) + 0.5f) / float(s), (float(j) + 0.5f) / float(s)};
            timeTiles(threads, w, h, [&](int x, int y) { rt.tile(f, x, y); });
            for (size_t p = 0; p < ref.shade.size(); ++p) {
                ref.shade[p] += f.shade[p] / float(s * s);
                ref.hit[p] |= f.hit[p];
            }
        }
    return ref;
}
constexpr int kReferenceRays = 4;  // per pixel edge: 16 rays a pixel

// CPU time this process has used (all threads): on a machine shared with other work the
// build's wall time mostly measures the others; its CPU time does not.
double processCpuMs() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    auto ms = [](const timeval& t) { return double(t.tv_sec) * 1e3 + double(t.tv_usec) * 1e-3; };
    return ms(u.ru_utime) + ms(u.ru_stime);
}

template <int N>
int run(const std::string& file, std::shared_ptr<PointScene> built, const PinholeCamera& cam, int w, int h, int all,
        int repeat, std::vector<float> qualities, std::vector<float> repScales, int leafSize, double loadMs,
        bool lodOnly) {
    const float quality = qualities.front();
    // The engine's scene renders; the rebuilds below only time the builder on its discs.
    PointScene& scene = *built;
    std::vector<Disc> discs = scene.discs();
    const size_t n = discs.size();
    std::printf("cpu: %s, isa %s (Embree capped at %s)\n", cpuModel().c_str(), simd::isaName(), embreeMaxIsa());
    std::printf(
        "file=%s\npoints=%zu\naccel=%s%s\nimage=%dx%d\npacket=%d\nthreads_all=%d\nlod_quality=%.3g\nrep_scale=%."
        "3g\nload_"
        "ms=%.1f\n",
        file.c_str(), n, scene.isWide() ? "wide" : "kd",
        !scene.isWide()                        ? ""
        : scene.wideSplit == LoDWideSplit::Sah ? " (sah)"
                                               : " (median)",
        w, h, N, all, quality, repScales.front(), loadMs);
    const std::vector<int> threadCounts = all > 1 ? std::vector<int>{1, all} : std::vector<int>{1};
    if (lodOnly) {  // quick A/B of the LoD traversal: no builds timed, no peer
        std::printf("memory: rtfact_bytes_per_point=%.2f\n", double(scene.memoryBytes()) / double(n));
        Frame ff(w, h), fl(w, h);
        RTfactSide<N> rt{scene, cam};
        scene.setLoD(cam.cone(), 0.0f);
        timeTiles(all, w, h, [&](int x, int y) { rt.tile(ff, x, y); });
        const Frame ref = supersampledFullDetail<N>(scene, cam, w, h, all, kReferenceRays);
        std::printf("object_psnr_vs_supersampled: full=%.2f (full detail, %dx%d rays a pixel, averaged)\n",
                    psnr8(ff, ref, true), kReferenceRays, kReferenceRays);
        for (float q : qualities) {
            scene.setLoD(cam.cone(), q, repScales.front());
            for (int T : threadCounts) {
                double lod = 1e30;
                for (int r = 0; r < repeat; ++r)
                    lod = std::min(lod, timeTiles(T, w, h, [&](int x, int y) { rt.tile(fl, x, y); }));
                std::printf(
                    "quality=%.3g threads=%d lod_frame_ms=%.1f psnr_lod_vs_full=%.2f object_psnr=%.2f "
                    "object_psnr_vs_supersampled=%.2f\n",
                    q, T, lod, psnr8(fl, ff), psnr8(fl, ff, true), psnr8(fl, ref, true));
            }
        }
        return 0;
    }
    LoDKdTreeBuilder builder;
    builder.maxLeafSize = leafSize;
    // Two builds a side: the first is what a user pays, the best (the second) what the
    // builder costs once its memory is backed. On VMs with free page reporting (virtio-
    // balloon: the CI machines) the host takes back freed memory, so a process's first touch
    // of it faults in the host: ~2 s per GiB there against 0.1 s for memory touched again at
    // once (docs/benchmarks.md, session 37), which the 32M cloud's 1.4 GB of tree pays.
    constexpr int kBuilds = 2;
    struct BuildTimes {
        double first = 0, best = 1e30;
        int count = 0;
        void add(double ms) {
            if (count++ == 0) first = ms;
            best = std::min(best, ms);
        }
    };
    BuildTimes rtTimes;
    double rtCpu = 1e30;
    {
        // Build at all threads (the target is points/s on all cores).
        tbb::task_arena arena(all);
        for (int r = 0; r < kBuilds; ++r) {
            std::vector<Disc> copy;
            resizeFreshHugePages(copy, discs.size());
            std::copy(discs.begin(), discs.end(), copy.begin());
            PointScene rebuilt;
            rebuilt.accel = scene.accel;
            rebuilt.wideSplit = scene.wideSplit;
            const auto t0 = Clock::now();
            const double c0 = processCpuMs();
            arena.execute([&] { rebuilt.build(std::move(copy), builder); });
            rtTimes.add(msSince(t0));
            rtCpu = std::min(rtCpu, processCpuMs() - c0);
        }
    }
    // Embree gets the same discs in the same (leaf) order.
    EmbreeSide em(discs, cam, all);
    BuildTimes emTimes;
    double emCpu = 1e30;
    {
        tbb::task_arena arena(all);
        for (int r = 0; r < kBuilds; ++r) {
            const double c0 = processCpuMs();
            arena.execute([&] { emTimes.add(em.build()); });
            emCpu = std::min(emCpu, processCpuMs() - c0);
        }
    }
    const double rtBytes = double(scene.memoryBytes());
    // Embree keeps its own copy of the points (16 B centre+radius, 12 B normal) plus the BVH.
    const double emBytes = double(gEmbreeBytes.load()) + double(n) * 28.0;
    std::printf("build_ms: rtfact=%.1f embree=%.1f ratio_build_time=%.3f rtfact_points_per_s=%.3g\n", rtTimes.best,
                emTimes.best, rtTimes.best / emTimes.best, double(n) / (rtTimes.best * 1e-3));
    std::printf(
        "build_first_ms: rtfact=%.1f embree=%.1f ratio_build_time=%.3f rtfact_points_per_s=%.3g (the first of "
        "%d builds, fresh memory)\n",
        rtTimes.first, emTimes.first, rtTimes.first / emTimes.first, double(n) / (rtTimes.first * 1e-3), kBuilds);
    // Points per CPU second: the load-independent figure (ideal 2-thread speed = 2x this).
    std::printf(
        "build_cpu_ms: rtfact=%.1f embree=%.1f ratio_build_cpu=%.3f rtfact_points_per_cpu_s=%.3g (embree: with filling "
        "its buffers)\n",
        rtCpu, emCpu, rtCpu / emCpu, double(n) / (rtCpu * 1e-3));
    std::printf(
        "memory: rtfact_bytes_per_point=%.2f embree_bytes_per_point=%.2f (embree: BVH from its monitor + 28 B/point "
        "buffers)\n",
        rtBytes / double(n), emBytes / double(n));

    Frame ff(w, h), fl(w, h), fe(w, h);
    RTfactSide<N> rt{scene, cam};
    const uint64_t rays = uint64_t(w) * uint64_t(h);
    auto mr = [&](double ms) { return double(rays) / (ms * 1000.0); };
    double worstFull = 1e30, worstLod = 1e30;
    for (int T : threadCounts) {
        double full = 1e30, lod = 1e30, emb = 1e30;
        for (int r = 0; r < repeat; ++r) {
            scene.setLoD(cam.cone(), 0.0f);
            full = std::min(full, timeTiles(T, w, h, [&](int x, int y) { rt.tile(ff, x, y); }));
            scene.setLoD(cam.cone(), quality, repScales.front());
            lod = std::min(lod, timeTiles(T, w, h, [&](int x, int y) { rt.tile(fl, x, y); }));
            emb = std::min(emb, timeTiles(T, w, h, [&](int x, int y) { em.tile(fe, x, y); }));
        }
        std::printf("threads=%d frame_ms: full=%.1f lod=%.1f embree=%.1f\n", T, full, lod, emb);
        std::printf("threads=%d mrays: full=%.2f lod=%.2f embree=%.2f ratio_full=%.3f ratio_lod=%.3f\n", T, mr(full),
                    mr(lod), mr(emb), emb / full, emb / lod);
        worstFull = std::min(worstFull, emb / full);
        worstLod = std::min(worstLod, emb / lod);
    }
    size_t hitDiff = 0;
    for (size_t i = 0; i < ff.hit.size(); ++i) hitDiff += ff.hit[i] != fe.hit[i];
    std::printf("agreement_full_vs_embree: hit_diff_pixels=%zu psnr=%.2f\n", hitDiff, psnr8(ff, fe));
    const Frame ref = supersampledFullDetail<N>(scene, cam, w, h, all, kReferenceRays);
    std::printf("psnr_lod_vs_full=%.2f object_psnr=%.2f\n", psnr8(fl, ff), psnr8(fl, ff, true));
    std::printf("object_psnr_vs_supersampled: full=%.2f lod=%.2f (full detail, %dx%d rays a pixel, averaged)\n",
                psnr8(ff, ref, true), psnr8(fl, ref, true), kReferenceRays, kReferenceRays);
    // Further qualities: all threads only.
    for (float s : repScales)
        for (size_t qi = s == repScales.front() ? 1 : 0; qi < qualities.size(); ++qi) {
            const float q = qualities[qi];
            double lod = 1e30, emb = 1e30;
            scene.setLoD(cam.cone(), q, s);
            for (int r = 0; r < repeat; ++r) {
                lod = std::min(lod, timeTiles(all, w, h, [&](int x, int y) { rt.tile(fl, x, y); }));
                emb = std::min(emb, timeTiles(all, w, h, [&](int x, int y) { em.tile(fe, x, y); }));
            }
            std::printf(
                "quality=%.3g rep_scale=%.3g threads=%d lod_frame_ms=%.1f embree_frame_ms=%.1f ratio_lod=%.3f "
                "lod_mrays=%.2f psnr_lod_vs_full=%.2f object_psnr=%.2f object_psnr_vs_supersampled=%.2f\n",
                q, s, all, lod, emb, emb / lod, mr(lod), psnr8(fl, ff), psnr8(fl, ff, true), psnr8(fl, ref, true));
        }
    std::printf("ratio_full=%.3f\nratio_lod=%.3f\n", worstFull, worstLod);
    std::printf("(ratios: Embree frame time / RTfact frame time, the worse of 1 and %d threads)\n", all);
    return 0;
}

}  // namespace

int benchPoints(int argc, char** argv) {
    CLI::App app{"RTfact LoD kd-tree discs vs Embree oriented-disc points", "rtfact-bench points"};
    std::string file, eye, at, up, size = "1024x1024", normals = "auto", accel = "kd", split = "sah";
    float fov = 45.0f, radius = 0.0f, radiusFactor = 1.0f;
    std::vector<float> quality{1.0f}, repScale{0.7f};
    int threads = 0, packet = engine::defaultPacketSize(engine::SceneKind::Points), repeat = 3, leafSize = 8;
    bool lodOnly = false;
    app.add_option("FILE", file, "Point cloud (.ply .pcd .xyz .pts)")->required();
    app.add_option("--eye", eye, "Camera position x,y,z");
    app.add_option("--at", at, "Camera target x,y,z");
    app.add_option("--up", up, "Camera up x,y,z");
    app.add_option("--fov", fov, "Vertical field of view (degrees)")->capture_default_str();
    app.add_option("--threads", threads, "All-threads figure uses this many (0: all cores)")->capture_default_str();
    app.add_option("--size", size, "Image size WxH")->capture_default_str();
    app.add_option("--packet", packet, "RTfact packet size: 1, 16, 64 or 256")
        ->capture_default_str()
        ->check(CLI::IsMember({1, 16, 64, 256}));
    app.add_option("--repeat", repeat,
                   "Runs per frame measurement (best is kept; builds always run twice, first and best printed)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100));
    app.add_option("--lod-quality", quality, "LoD quality for the LoD run (more values: extra LoD runs at all threads)")
        ->capture_default_str()
        ->check(CLI::Range(0.0f, 64.0f));
    app.add_option("--rep-scale", repScale,
                   "Hit radius of representatives / covering radius (more values: extra LoD runs)")
        ->capture_default_str()
        ->check(CLI::Range(0.1f, 1.0f));
    app.add_option("--accel", accel, "RTfact structure: kd (the LoD kd-tree, the default) or wide (BVH of disc blocks)")
        ->capture_default_str()
        ->check(CLI::IsMember({"wide", "kd"}));
    app.add_option("--wide-split", split, "Wide BVH build: sah (the default) or median (faster build)")
        ->capture_default_str()
        ->check(CLI::IsMember({"sah", "median"}));
    app.add_option("--leaf-size", leafSize, "Maximum points per kd-tree leaf")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    app.add_flag("--lod-only", lodOnly,
                 "Only the LoD frames (and PSNR against one full frame): no builds timed, no Embree");
    app.add_option("--radius", radius, "Disc radius for every point");
    app.add_option("--radius-factor", radiusFactor, "Scale of the radii")->capture_default_str();
    app.add_option("--normals", normals, "auto|estimate|file")->capture_default_str();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return usageExit(app, e);
    }
    int w = 1024, h = 1024;
    if (std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 16 || h < 16 || w > 16384 || h > 16384 || w % 16 ||
        h % 16)
        throw Error("", "--size: expected WxH, multiples of 16 in 16..16384");
    setProgressEnabled(false);
    // Loading, preparation (normals, radii, colours) and the build are the engine's, as
    // for `rtfact points`; the camera is the CLI's default view unless given.
    engine::OpenOptions oo;
    oo.kind = engine::SceneKind::Points;
    oo.progress = false;
    oo.keepSource = false;
    const auto t0 = Clock::now();
    const engine::Scene sc = engine::open({file}, oo);
    const double loadMs = msSince(t0);
    engine::Settings settings;
    settings.points.normals = normals;
    settings.points.radius = radius;
    settings.points.radiusFactor = radiusFactor;
    settings.points.leafSize = leafSize;
    CameraFrame frame = engine::fitCamera(sc.defaultView(settings), fov, float(w) / float(h));
    if (!eye.empty()) frame.eye = parseVec(eye, "--eye");
    if (!at.empty()) frame.at = parseVec(at, "--at");
    if (!up.empty()) frame.up = parseVec(up, "--up");
    frame.fovDeg = fov;
    const PinholeCamera cam(frame, w, h);
    std::shared_ptr<PointScene> scene = engine::builtPoints(sc, settings, frame);
    if (accel == "wide") {  // the engine builds the default structure (kd); the wide one from its discs
        auto other = std::make_shared<PointScene>();
        other->accel = accel == "kd" ? PointAccel::KdTree : PointAccel::Wide;
        other->wideSplit = split == "median" ? LoDWideSplit::Median : LoDWideSplit::Sah;
        other->colorMode = scene->colorMode;
        LoDKdTreeBuilder b;
        b.maxLeafSize = leafSize;
        other->build(scene->discs(), b);
        scene = other;
    }
    const int all = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
    switch (packet) {
        case 1:
            return run<1>(file, scene, cam, w, h, all, repeat, quality, repScale, leafSize, loadMs, lodOnly);
        case 16:
            return run<16>(file, scene, cam, w, h, all, repeat, quality, repScale, leafSize, loadMs, lodOnly);
        case 256:
            return run<256>(file, scene, cam, w, h, all, repeat, quality, repScale, leafSize, loadMs, lodOnly);
        default:
            return run<64>(file, scene, cam, w, h, all, repeat, quality, repScale, leafSize, loadMs, lodOnly);
    }
}

}  // namespace rtfact::bench
