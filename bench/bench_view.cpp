// rtfact-bench view FILE: the viewer through a real socket with a scripted client (the
// protocol the page speaks): latency from a camera message to its first frame, frames/s
// while orbiting and the effective resolution of those previews, and the time from the
// orbit's end to the refined full-resolution frame, against the one-shot render the CLI
// does for the same view (engine::renderToImage) in the same process.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include "apps/view/viewer_client.h"
#include "apps/view/viewer_server.h"
#include "bench/bench_commands.h"
#include "bench/bench_common.h"
#include "engine/render_session.h"

namespace rtfact::bench {

namespace {

std::string loadAverage() {
    std::ifstream in("/proc/loadavg");
    std::string a;
    in >> a;
    return a.empty() ? "?" : a;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// The camera orbited by `deg` degrees about the up axis through the target.
CameraFrame orbit(const CameraFrame& c, float deg) {
    const float t = deg * 3.14159265f / 180.0f;
    const Vec3f k = normalize(c.up), v = c.eye - c.at;
    const Vec3f r = v * std::cos(t) + cross(k, v) * std::sin(t) + k * (dot(k, v) * (1 - std::cos(t)));
    CameraFrame o = c;
    o.eye = c.at + r;
    return o;
}

}  // namespace

int benchView(int argc, char** argv) {
    CLI::App app{"rtfact-bench view: the browser viewer's latency, orbit frame rate and refinement over a socket"};
    std::string file, size = "1024x1024";
    int threads = 2, orbitFrames = 60;
    float frameMs = 40.0f;
    app.add_option("FILE", file, "Data file (kind detected as by `rtfact view FILE`)")->required();
    app.add_option("--size", size, "Full resolution WxH")->capture_default_str();
    app.add_option("--threads", threads, "Render threads (0: all cores)")->capture_default_str();
    app.add_option("--orbit-frames", orbitFrames, "Frames in the orbit")
        ->capture_default_str()
        ->check(CLI::Range(5, 100000));
    app.add_option("--frame-ms", frameMs, "Preview frame-time target")->capture_default_str();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return usageExit(app, e);
    }
    int w = 0, h = 0;
    if (std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 16 || h < 16) throw Error("--size", "expected WxH");
    engine::OpenOptions oo;
    oo.progress = false;
    const engine::Scene scene = engine::open({file}, oo);
    const engine::Settings settings;
    const CameraFrame home = engine::fitCamera(scene.defaultView(settings), 45.0f, float(w) / float(h));

    // The CLI's render of the refined view (1 spp, full resolution): best of three after a
    // warm-up that builds the acceleration structure.
    engine::FrameOptions fo;
    fo.width = w;
    fo.height = h;
    fo.threads = threads;
    const CameraFrame last = orbit(home, 2.0f * float(orbitFrames));
    double cliMs = 1e30;
    for (int i = 0; i < 4; ++i) {
        engine::Stats st;
        const auto t0 = Clock::now();
        engine::renderToImage(scene, settings, fo, i == 0 ? home : last, 1, st);
        if (i > 0) cliMs = std::min(cliMs, msSince(t0));
    }

    viewer::ViewerConfig cfg;
    cfg.settings = settings;
    cfg.frame = fo;
    cfg.home = home;
    cfg.maxSamples = 1;
    cfg.frameMs = frameMs;
    viewer::ViewerServer server(scene, cfg, {});
    server.start();
    using namespace viewer::client;
    WsClient c(server.port(), server.token());
    auto message = [](const CameraFrame& cam, bool moving) {
        json j = viewer::cameraJson(cam);
        j["type"] = "camera";
        j["moving"] = moving;
        return j;
    };
    auto of = [](const CameraFrame& cam) {
        return [j = viewer::cameraJson(cam)](const json& m) { return m["camera"] == j; };
    };
    c.frame([](const json& m) { return m["scale"] == 1; });  // the first refined frame (warm)

    // Orbit: the page's loop (a camera message, its frame, the next camera).
    std::vector<double> latency, passMs;
    double pixels = 0;
    int scaleMax = 1;
    const auto orbitT0 = Clock::now();
    for (int i = 1; i <= orbitFrames; ++i) {
        const CameraFrame cam = orbit(home, 2.0f * float(i));
        const auto t0 = Clock::now();
        c.send(message(cam, true));
        const FrameMsg f = c.frame(of(cam));
        latency.push_back(msSince(t0));
        passMs.push_back(f.meta["ms"].get<double>());
        pixels += double(f.meta["width"].get<int>()) * double(f.meta["height"].get<int>());
        scaleMax = std::max(scaleMax, f.meta["scale"].get<int>());
    }
    const double orbitMs = msSince(orbitT0);
    const double fps = 1000.0 * orbitFrames / orbitMs;
    const double effective = std::sqrt(pixels / orbitFrames);
    // The orbit ends: the refined full-resolution frame of the last camera.
    const auto t0 = Clock::now();
    c.send(message(last, false));
    const FrameMsg refined = c.frame([&](const json& m) { return of(last)(m) && m["scale"] == 1; });
    const double refineMs = msSince(t0);
    server.stop();

    const double lat = median(latency);
    std::vector<double> sorted = latency;
    std::sort(sorted.begin(), sorted.end());
    const double p90 = sorted[size_t(double(sorted.size() - 1) * 0.9)];
    std::printf("rtfact-bench view %s (%s, %dx%d, %d threads, preview target %.0f ms)\n", file.c_str(),
                engine::kindName(scene.kind()), w, h, threads, double(frameMs));
    std::printf("CPU: %s; load average at the end: %s\n", cpuModel().c_str(), loadAverage().c_str());
    std::printf("%-44s %10s %10s %s\n", "measure", "ours", "target", "");
    std::printf("%-44s %10.1f %10s %s\n", "camera message -> first preview frame, ms (median)", lat, "<= 50",
                lat <= 50 ? "ok" : "MISSED");
    std::printf("%-44s %10.1f %10s\n", "camera message -> first preview frame, ms (p90)", p90, "");
    std::printf("%-44s %10.1f %10s\n", "  of which the preview pass, ms (median)", median(passMs), "");
    std::printf("%-44s %10.1f %10s %s\n", "frames/s while orbiting", fps, ">= 15", fps >= 15 ? "ok" : "MISSED");
    std::printf("%-44s %7.0fx%-3.0f %10s %s (max scale 1/%d)\n", "effective preview resolution (mean)",
                effective * w / std::sqrt(double(w) * h), effective * h / std::sqrt(double(w) * h), ">= 512^2",
                effective >= 512 ? "ok" : "MISSED", scaleMax);
    std::printf("%-44s %10.1f\n", "CLI one-shot render, ms (best of 3)", cliMs);
    std::printf("%-44s %10.1f\n", "orbit end -> refined full-res frame, ms", refineMs);
    std::printf("%-44s %10.2f %10s %s\n", "refined / CLI (ratio)", refineMs / cliMs, "<= 1.2",
                refineMs / cliMs <= 1.2 ? "ok" : "MISSED");
    std::printf("refined frame: %dx%d, %zu bytes JPEG\n", refined.meta["width"].get<int>(),
                refined.meta["height"].get<int>(), refined.bytes.size());
    return 0;
}

}  // namespace rtfact::bench
