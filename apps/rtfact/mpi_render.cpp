#include "apps/rtfact/mpi_render.h"

#include <mpi.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "apps/rtfact/mpi_common.h"
#include "apps/rtfact/mpi_data.h"
#include "apps/rtfact/render_command.h"
#include "core/render/image_io.h"
#include "core/util/error.h"
#include "core/util/progress.h"
#include "engine/render_session.h"
#include "engine/usage_error.h"

namespace rtfact::app {

using mpi::attempt;
using mpi::Mpi;
using mpi::Outcome;

namespace {

constexpr int kRequestTag = 1, kTileTag = 2;
constexpr int kWantTile = 0, kFailed = 1;  // what a worker's request says

// What each rank reports for --stats.
struct RankFigures {
    double renderMs = 0, rays = 0, tiles = 0, bytes = 0;
};

}  // namespace

bool mpiLaunched() {
    for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
        if (const char* v = std::getenv(var)) return std::atoi(v) > 1;
    return false;
}

int runMpiRender(CommonOptions& c, const std::function<engine::Settings()>& settings,
                 const std::function<engine::Scene()>& open, const DataSource* data) {
    Mpi mpi;
    const bool root = mpi.rank == 0;
    if (int st =
            mpi.agree(mpi.serialized ? Outcome{} : Outcome{1, "the MPI library does not offer MPI_THREAD_SERIALIZED"}))
        return st;
    std::string mode;
    if (int st = mpi.agree(attempt([&] { mode = chooseDistribution(c, data, mpi.size); }))) return st;
    if (mode == "data") return runMpiData(mpi, c, settings, *data);

    // Every rank loads the scene; a rank that cannot (a file only some ranks can read)
    // ends them all.
    if (!root) c.quiet = true;  // one progress display and one set of warnings: rank 0's
    RenderJob job;
    if (int st = mpi.agree(attempt([&] { job = prepareRender(c, settings, open, root); }))) return st;
    if (root && !c.quiet)
        std::fprintf(stderr, "rtfact: mpi: %d ranks, --distribute image (every rank holds the scene)%s\n", mpi.size,
                     c.distribute.empty() ? ", chosen: the data fits every rank" : "");
    // Eye-dome lighting filters the whole depth image, which no rank holds: the ranks
    // render without it and hand in their tiles' depth; rank 0 applies it to the assembled
    // image, as one process applies it to its own.
    const float edl = engine::eyeDomeStrength(job.scene, job.settings);
    if (edl > 0) {
        job.settings.points.edl = 0.0f;
        job.frame.depth = true;
    }
    const size_t ch = edl > 0 ? 5 : 4;  // floats per pixel gathered: RGBA (and depth)

    const TileGrid grid(c.width, c.height, RenderOptions{}.tileSize);
    const int tiles = grid.count();
    job.frame.progress = false;  // rank 0 shows the tiles handed out instead
    RankFigures mine;
    engine::Frame image;
    Outcome rendered;
    engine::Stats renderStats;
    auto render = [&] {
        rendered = attempt(
            [&] { image = engine::renderToImage(job.scene, job.settings, job.frame, job.camera, c.spp, renderStats); });
    };
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<int> myTiles;  // workers: the tiles this rank rendered
    if (root) {
        // The tiles go to whoever asks next: rank 0's own render threads take them from
        // the counter, the main thread answers the other ranks.
        std::atomic<int> next{0};
        Progress progress("render (" + std::to_string(mpi.size) + " ranks)", uint64_t(tiles), !c.quiet);
        auto claim = [&] {
            const int t = next.fetch_add(1);
            if (t >= tiles) return -1;
            progress.add();
            return t;
        };
        std::atomic<int> ownTiles{0};
        job.frame.nextTile = [&] {
            const int t = claim();
            if (t >= 0) ++ownTiles;
            return t;
        };
        std::thread renderer([&] {
            render();
            if (rendered.status) next.store(tiles);  // the others stop asking
        });
        int waiting = mpi.size - 1;
        while (waiting > 0) {
            int flag = 0;
            MPI_Status status;
            MPI_Iprobe(MPI_ANY_SOURCE, kRequestTag, MPI_COMM_WORLD, &flag, &status);
            if (!flag) {
                // Polling gently leaves the cores to the renderers.
                std::this_thread::sleep_for(std::chrono::microseconds(50));
                continue;
            }
            int request = 0;
            MPI_Recv(&request, 1, MPI_INT, status.MPI_SOURCE, kRequestTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            mine.bytes += sizeof request;
            if (request == kFailed) {
                next.store(tiles);  // the frame is lost: the others stop early
                --waiting;
                continue;
            }
            const int t = claim();
            MPI_Send(&t, 1, MPI_INT, status.MPI_SOURCE, kTileTag, MPI_COMM_WORLD);
            mine.bytes += sizeof t;
            if (t < 0) --waiting;
        }
        renderer.join();
        progress.finish();
        mine.tiles = ownTiles.load();
    } else {
        std::mutex asking;
        bool exhausted = false;
        job.frame.nextTile = [&] {
            std::lock_guard l(asking);
            if (exhausted) return -1;
            int request = kWantTile, t = -1;
            MPI_Send(&request, 1, MPI_INT, 0, kRequestTag, MPI_COMM_WORLD);
            MPI_Recv(&t, 1, MPI_INT, 0, kTileTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            mine.bytes += sizeof request + sizeof t;
            if (t < 0)
                exhausted = true;
            else
                myTiles.push_back(t);
            return t;
        };
        render();
        if (rendered.status && !exhausted) {
            // Rank 0 still counts on this rank asking: tell it not to.
            const int request = kFailed;
            MPI_Send(&request, 1, MPI_INT, 0, kRequestTag, MPI_COMM_WORLD);
        }
        mine.tiles = double(myTiles.size());
    }
    mine.renderMs = engine::msSince(t0);
    mine.rays = std::atof(renderStats.get("rays").c_str());
    if (int st = mpi.agree(rendered)) return st;

    // Rank 0 gathers the other ranks' tiles (their pixels, resolved as in its own frame).
    const auto g0 = std::chrono::steady_clock::now();
    std::vector<float> pixels;
    for (int t : myTiles) {
        const Region r = grid.region(t);
        for (int y = r.y0; y < r.y1; ++y)
            for (int x = r.x0; x < r.x1; ++x) {
                const size_t i = size_t(y) * size_t(grid.width) + size_t(x);
                pixels.insert(pixels.end(), image.rgba.data() + i * 4, image.rgba.data() + i * 4 + 4);
                if (ch == 5) pixels.push_back(image.depth[i]);
            }
    }
    if (!root) mine.bytes += double(myTiles.size() * sizeof(int) + pixels.size() * sizeof(float));
    const Outcome gathered = attempt([&] {
        int count = int(myTiles.size());
        std::vector<int> counts(size_t(root ? mpi.size : 0)), offsets(counts.size());
        MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
        int all = 0;
        for (size_t r = 0; r < counts.size(); ++r) offsets[r] = std::exchange(all, all + counts[r]);
        std::vector<int> tileOf(static_cast<size_t>(all));
        MPI_Gatherv(myTiles.data(), count, MPI_INT, tileOf.data(), counts.data(), offsets.data(), MPI_INT, 0,
                    MPI_COMM_WORLD);
        // Each rank's floats, from its tiles' sizes.
        std::vector<int> floatCounts(counts.size()), floatOffsets(counts.size());
        int floats = 0;
        for (size_t r = 0, i = 0; r < counts.size(); ++r) {
            floatOffsets[r] = floats;
            for (int k = 0; k < counts[r]; ++k, ++i) {
                const Region reg = grid.region(tileOf[i]);
                floatCounts[r] += (reg.x1 - reg.x0) * (reg.y1 - reg.y0) * int(ch);
            }
            floats += floatCounts[r];
        }
        std::vector<float> received(static_cast<size_t>(floats));
        MPI_Gatherv(pixels.data(), int(pixels.size()), MPI_FLOAT, received.data(), floatCounts.data(),
                    floatOffsets.data(), MPI_FLOAT, 0, MPI_COMM_WORLD);
        if (!root) return;
        mine.bytes += double(tileOf.size() * sizeof(int) + received.size() * sizeof(float));
        const float* p = received.data();
        for (int t : tileOf) {
            const Region r = grid.region(t);
            for (int y = r.y0; y < r.y1; ++y)
                for (int x = r.x0; x < r.x1; ++x, p += ch) {
                    const size_t i = size_t(y) * size_t(grid.width) + size_t(x);
                    std::copy(p, p + 4, image.rgba.data() + i * 4);
                    if (ch == 5) image.depth[i] = p[4];
                }
        }
    });
    // A failure here leaves the others inside a collective: end them all.
    if (gathered.status) mpi.abort(gathered);
    const double gatherMs = engine::msSince(g0);

    const double figures[4] = {mine.renderMs, mine.rays, mine.tiles, mine.bytes};
    std::vector<double> all(root ? size_t(mpi.size) * 4 : 0);
    MPI_Gather(figures, 4, MPI_DOUBLE, all.data(), 4, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (!root) return 0;

    const Outcome written = attempt([&] {
        engine::applyEyeDomeLighting(image, edl);
        writeImage(c.out, image.width, image.height, image.rgba);
    });
    if (written.status) {
        std::fprintf(stderr, "rtfact: error: rank 0: %s\n", written.message.c_str());
        return written.status;
    }
    if (c.stats) {
        job.stats.append(renderStats);
        job.stats.add("mpi_ranks", mpi.size);
        job.stats.add("mpi_distribute", "image");
        job.stats.add("mpi_tiles", tiles);
        job.stats.add("mpi_gather_ms", gatherMs);
        for (int r = 0; r < mpi.size; ++r) {
            const std::string k = "rank" + std::to_string(r) + "_";
            job.stats.add(k + "render_ms", all[size_t(r) * 4]);
            job.stats.add(k + "rays", (unsigned long long)all[size_t(r) * 4 + 1]);
            job.stats.add(k + "tiles", (unsigned long long)all[size_t(r) * 4 + 2]);
            job.stats.add(k + "bytes", (unsigned long long)all[size_t(r) * 4 + 3]);
        }
        job.stats.print();
    }
    return 0;
}

}  // namespace rtfact::app
