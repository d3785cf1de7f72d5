#include "apps/rtfact/mpi_data.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/render/image_io.h"
#include "distributed/point_parts.h"
#include "distributed/sort_last_compositor.h"
#include "distributed/volume_parts.h"
#include "engine/render_session.h"
#include "engine/stats.h"
#include "engine/volume_part.h"
#include "points/point_cloud_io.h"
#include "points/point_prepare.h"

namespace rtfact::app {

using mpi::attempt;
using mpi::Outcome;

namespace {

// A /proc/self/status or /proc/meminfo figure in kB (0 when absent).
uint64_t procKb(const char* file, const std::string& key) {
    std::ifstream f(file);
    std::string line;
    while (std::getline(f, line))
        if (line.rfind(key + ":", 0) == 0) return std::strtoull(line.c_str() + key.size() + 1, nullptr, 10);
    return 0;
}

// Bytes of the files a volume's voxels are in (the .raw next to a .mhd/.nhdr counts).
uint64_t dataBytes(const std::string& file) {
    namespace fs = std::filesystem;
    std::error_code ec;
    uint64_t n = fs::is_regular_file(file, ec) ? uint64_t(fs::file_size(file, ec)) : 0;
    const std::string ext = fs::path(file).extension().string();
    if (ext == ".mhd" || ext == ".nhdr")
        for (const char* e : {".raw", ".raw.gz", ".zraw"}) {
            const fs::path p = fs::path(file).replace_extension(e);
            if (fs::is_regular_file(p, ec)) n += uint64_t(fs::file_size(p, ec));
        }
    return n;
}

// The rank figures of --stats, gathered on rank 0 (kLoaded: voxel bytes or points owned).
enum Figure { kLoadMs, kRenderMs, kCompositeMs, kBytes, kLoaded, kHwm, kGhosts, kFigures };

int runMpiPointData(const mpi::Mpi& mpi, CommonOptions& c, const std::function<engine::Settings()>& settings,
                    const DataSource& data);

// Every rank parses the options into `s`, `check` rejects what this data-parallel mode
// cannot render (a usage error), rank 0 checks the output path; a rank that fails ends
// them all. Returns the exit status to stop with, 0 to go on.
int agreeOnOptions(const mpi::Mpi& mpi, CommonOptions& c, const std::function<engine::Settings()>& settings,
                   engine::Settings& s, const std::function<void(const engine::Settings&)>& check) {
    if (mpi.rank != 0) c.quiet = true;
    return mpi.agree(attempt([&] {
        c.finalize();
        s = settings();
        check(s);
        if (mpi.rank == 0) checkImageWritable(c.out);
    }));
}

}  // namespace

std::string chooseDistribution(const CommonOptions& c, const DataSource* data, int ranks) {
    if (c.distribute == "data" && !data)
        throw engine::UsageError("--distribute",
                                 "data: data-parallel rendering is for volumes and point clouds (rtfact volume, "
                                 "rtfact points)");
    if (!c.distribute.empty()) return c.distribute;
    if (!data) return "image";
    // Image-parallel holds the whole data on every rank of this node: a volume dense and
    // bricked while loading (about twice the voxel bytes), a cloud while it is prepared
    // and its tree built (the engine's calibrated peak, estimating normals and radii).
    uint64_t perRank = 0;
    if (data->kind == engine::SceneKind::Volume) {
        perRank = 2 * dataBytes(data->file);
    } else {
        const auto probe = points::probePointFile(data->file);
        perRank = probe ? points::pointPipelineBytes(probe->points, true, true) : 0;
    }
    const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
    const uint64_t perNode = uint64_t(std::max(1, local ? std::atoi(local) : ranks));
    const uint64_t avail = procKb("/proc/meminfo", "MemAvailable") * 1024;
    return avail == 0 || perRank * perNode <= avail ? "image" : "data";
}

int runMpiData(const mpi::Mpi& mpi, CommonOptions& c, const std::function<engine::Settings()>& settings,
               const DataSource& data) {
    if (data.kind == engine::SceneKind::Points) return runMpiPointData(mpi, c, settings, data);
    const bool root = mpi.rank == 0;
    engine::Settings s;
    engine::VolumePart part;
    double fig[kFigures] = {};
    // Options first, then each rank reads its slab; a rank that cannot ends them all.
    if (int st = agreeOnOptions(mpi, c, settings, s, [](const engine::Settings& o) {
            if (o.volume.mode != "dvr" && o.volume.mode != "shaded")
                throw engine::UsageError("--mode", o.volume.mode +
                                                       " is not composited across slabs yet: --distribute data "
                                                       "renders dvr and shaded; use --distribute image");
        }))
        return st;
    const auto t0 = std::chrono::steady_clock::now();
    if (int st = mpi.agree(attempt([&] {
            engine::OpenOptions o = data.options();
            o.progress = !c.quiet;
            part = engine::loadVolumePart(data.file, o, mpi.rank, mpi.size, engine::ghostSlices(s.volume));
        })))
        return st;
    fig[kLoadMs] = engine::msSince(t0);
    fig[kLoaded] = double(part.loadedBytes);
    if (root && !c.quiet) {
        std::fprintf(stderr, "rtfact: mpi: %d ranks, --distribute data (each rank reads a slab of %d x %d x %d)%s\n",
                     mpi.size, part.dims[0], part.dims[1], part.dims[2],
                     c.distribute.empty() ? ", chosen: the volume does not fit every rank" : "");
        if (part.readWhole)
            std::fprintf(stderr,
                         "rtfact: warning: %s: this format has no slab access: every rank reads it whole "
                         "and keeps its slab\n",
                         data.file.c_str());
    }

    // One transfer function and window for every rank, from the whole volume.
    if (int st = mpi.agree(attempt([&] { distributed::agreeOnTransferFunction(MPI_COMM_WORLD, part, s); }))) return st;

    // Render this slab: premultiplied RGBA (the volume integrator's background is black).
    const auto r0 = std::chrono::steady_clock::now();
    engine::Frame image;
    engine::Stats renderStats;
    const AABB whole = engine::wholeClippedBox(part, s.volume);
    const CameraFrame camera = c.frame(whole, {0.45f, -1.0f, 0.35f}, {0, 0, 1});
    if (int st = mpi.agree(attempt([&] {
            engine::Scene scene = engine::partScene(part);
            engine::FrameOptions frame;
            frame.width = c.width;
            frame.height = c.height;
            frame.packet = c.packet;
            frame.threads = c.threads;
            frame.progress = !c.quiet;
            frame.target = c.out;
            if (const std::optional<engine::Settings> ps = engine::partSettings(part, s))
                image = engine::renderToImage(scene, *ps, frame, camera, c.spp, renderStats);
            else
                image.rgba.assign(size_t(c.width) * size_t(c.height) * 4, 0.0f);  // clipped away
        })))
        return st;
    fig[kRenderMs] = engine::msSince(r0);

    const std::vector<int> order = distributed::slabVisibilityOrder(part, mpi.size, camera.eye);
    distributed::CompositeFigures cf;
    std::vector<float> out;
    const Outcome composited = attempt([&] {
        out = distributed::composite(MPI_COMM_WORLD, image.rgba, c.width, c.height, distributed::CompositeOp::Over,
                                     order, &cf);
    });
    if (composited.status) mpi.abort(composited);  // out of step inside a collective
    fig[kCompositeMs] = cf.exchangeMs + cf.blendMs + cf.gatherMs;
    fig[kBytes] = double(cf.bytesSent + cf.bytesReceived);
    fig[kHwm] = double(procKb("/proc/self/status", "VmHWM"));
    std::vector<double> all(root ? size_t(mpi.size) * kFigures : 0);
    MPI_Gather(fig, kFigures, MPI_DOUBLE, all.data(), kFigures, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (!root) return 0;

    const Outcome written = attempt([&] { writeImage(c.out, c.width, c.height, out); });
    if (written.status) {
        std::fprintf(stderr, "rtfact: error: rank 0: %s\n", written.message.c_str());
        return written.status;
    }
    if (c.stats) {
        engine::Stats st;
        st.add("mpi_ranks", mpi.size);
        st.add("mpi_distribute", "data");
        st.add("volume_dims",
               std::to_string(part.dims[0]) + "x" + std::to_string(part.dims[1]) + "x" + std::to_string(part.dims[2]));
        st.add("mpi_ghost_slices", part.ghosts);
        for (int r = 0; r < mpi.size; ++r) {
            const double* f = &all[size_t(r) * kFigures];
            const std::string k = "rank" + std::to_string(r) + "_";
            const auto [a, b] = engine::slabPlanes(part.dims[2], r, mpi.size);
            st.add(k + "slab", std::to_string(a) + ".." + std::to_string(b));
            st.add(k + "load_ms", f[kLoadMs]);
            st.add(k + "render_ms", f[kRenderMs]);
            st.add(k + "composite_ms", f[kCompositeMs]);
            st.add(k + "bytes", (unsigned long long)f[kBytes]);
            st.add(k + "loaded_bytes", (unsigned long long)f[kLoaded]);
            st.add(k + "vmhwm_kb", (unsigned long long)f[kHwm]);
        }
        st.print();
    }
    return 0;
}

namespace {

// Point clouds: each rank renders the discs whose centres lie in its cell, with the depth;
// the ranks keep the nearest hit per pixel, and rank 0 applies eye-dome lighting to the
// composited image from the composited depth.
int runMpiPointData(const mpi::Mpi& mpi, CommonOptions& c, const std::function<engine::Settings()>& settings,
                    const DataSource& data) {
    const bool root = mpi.rank == 0;
    engine::Settings s;
    distributed::PointPart part;
    double fig[kFigures] = {};
    if (int st = agreeOnOptions(mpi, c, settings, s, [](const engine::Settings& o) {
            // Lights placed from the cloud's box (direct, whitted) and rays that meet other
            // parts' points (ao, path) need the whole cloud.
            if (o.points.integrator != "eyelight")
                throw engine::UsageError("--integrator", o.points.integrator +
                                                             ": --distribute data renders point clouds with eyelight; "
                                                             "use --distribute image");
        }))
        return st;
    if (int st = mpi.agree(attempt([&] {
            engine::OpenOptions o = data.options();
            o.progress = false;  // every rank reads the file: no bars over each other
            part = distributed::loadPointPart(data.file, o, s, mpi.rank, mpi.size);
        })))
        return st;
    fig[kLoadMs] = part.loadMs;
    fig[kLoaded] = double(part.owned);
    fig[kGhosts] = double(part.ghosts);
    if (root && !c.quiet) {
        std::fprintf(stderr,
                     "rtfact: mpi: %d ranks, --distribute data (each rank keeps the points of one cell along %c; "
                     "the file is read whole and cut)%s\n",
                     mpi.size, "xyz"[part.axis],
                     c.distribute.empty() ? ", chosen: the cloud does not fit every rank" : "");
        for (const std::string& w : part.warnings) std::fprintf(stderr, "rtfact: warning: %s\n", w.c_str());
    }

    const CameraFrame camera = c.frame(part.view.focus, part.view.viewDir, part.view.up);
    const auto r0 = std::chrono::steady_clock::now();
    engine::Frame image;
    if (int st = mpi.agree(attempt([&] {
            engine::Settings ps;
            const engine::Scene scene = distributed::preparePointPart(part, camera.eye, ps);
            engine::FrameOptions frame;
            frame.width = c.width;
            frame.height = c.height;
            frame.packet = c.packet;
            frame.threads = c.threads;
            frame.progress = !c.quiet;
            frame.target = c.out;
            frame.depth = true;
            engine::Stats renderStats;
            image = engine::renderToImage(scene, ps, frame, camera, c.spp, renderStats);
        })))
        return st;
    fig[kRenderMs] = engine::msSince(r0);

    // RGBA and depth per pixel; the nearest depth wins.
    const size_t pixels = size_t(c.width) * size_t(c.height);
    distributed::CompositeFigures cf;
    std::vector<float> out;
    const Outcome composited = attempt([&] {
        std::vector<float> mine(pixels * 5);
        for (size_t i = 0; i < pixels; ++i) {
            std::copy_n(image.rgba.data() + i * 4, 4, mine.data() + i * 5);
            mine[i * 5 + 4] = image.depth[i];
        }
        image = {};
        out = distributed::composite(MPI_COMM_WORLD, mine, c.width, c.height, distributed::CompositeOp::Depth, {}, &cf);
    });
    if (composited.status) mpi.abort(composited);  // out of step inside a collective
    fig[kCompositeMs] = cf.exchangeMs + cf.blendMs + cf.gatherMs;
    fig[kBytes] = double(cf.bytesSent + cf.bytesReceived);
    fig[kHwm] = double(procKb("/proc/self/status", "VmHWM"));
    std::vector<double> all(root ? size_t(mpi.size) * kFigures : 0);
    MPI_Gather(fig, kFigures, MPI_DOUBLE, all.data(), kFigures, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (!root) return 0;

    const Outcome written = attempt([&] {
        engine::Frame f;
        f.width = c.width;
        f.height = c.height;
        f.rgba.resize(pixels * 4);
        f.depth.resize(pixels);
        for (size_t i = 0; i < pixels; ++i) {
            std::copy_n(out.data() + i * 5, 4, f.rgba.data() + i * 4);
            f.depth[i] = out[i * 5 + 4];
        }
        out = {};
        engine::applyEyeDomeLighting(f, part.edl);
        writeImage(c.out, f.width, f.height, f.rgba);
    });
    if (written.status) {
        std::fprintf(stderr, "rtfact: error: rank 0: %s\n", written.message.c_str());
        return written.status;
    }
    if (c.stats) {
        engine::Stats st;
        st.add("mpi_ranks", mpi.size);
        st.add("mpi_distribute", "data");
        st.add("points", (unsigned long long)part.points);
        st.add("mpi_cut_axis", std::string(1, "xyz"[part.axis]));
        st.add("edl", double(part.edl));
        for (int r = 0; r < mpi.size; ++r) {
            const double* f = &all[size_t(r) * kFigures];
            const std::string k = "rank" + std::to_string(r) + "_";
            st.add(k + "points", (unsigned long long)f[kLoaded]);
            st.add(k + "ghost_points", (unsigned long long)f[kGhosts]);
            st.add(k + "load_ms", f[kLoadMs]);
            st.add(k + "render_ms", f[kRenderMs]);
            st.add(k + "composite_ms", f[kCompositeMs]);
            st.add(k + "bytes", (unsigned long long)f[kBytes]);
            st.add(k + "vmhwm_kb", (unsigned long long)f[kHwm]);
        }
        st.print();
    }
    return 0;
}

}  // namespace

}  // namespace rtfact::app
