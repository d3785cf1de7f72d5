#include "apps/rtfact/mpi_view.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "apps/rtfact/mpi_common.h"
#include "apps/view/protocol.h"
#include "core/render/tile_scheduler.h"
#include "core/util/error.h"
#include "engine/stats.h"

namespace rtfact::app {

using mpi::attempt;
using mpi::Outcome;
using nlohmann::json;

namespace {

constexpr int kCommandTag = 11, kReplyTag = 12;
constexpr int kFloats = 5;  // per pixel gathered: RGBA and depth

// Waits for a message from `source` without spinning a core (the renderers need them).
MPI_Status waitFor(int source, int tag, std::chrono::microseconds nap) {
    for (;;) {
        int flag = 0;
        MPI_Status st;
        MPI_Iprobe(source, tag, MPI_COMM_WORLD, &flag, &st);
        if (flag) return st;
        std::this_thread::sleep_for(nap);
    }
}

template <class T>
std::vector<T> receive(int source, int tag, MPI_Datatype type, std::chrono::microseconds nap) {
    MPI_Status st = waitFor(source, tag, nap);
    int n = 0;
    MPI_Get_count(&st, type, &n);
    std::vector<T> v(size_t(std::max(0, n)));
    MPI_Recv(v.data(), n, type, source, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    return v;
}

// The tiles rank `rank` of `ranks` renders of a w x h pass, in order.
std::vector<int> tilesOf(int rank, int ranks, int w, int h) {
    const int n = TileGrid(w, h, RenderOptions{}.tileSize).count();
    std::vector<int> t;
    for (int i = rank; i < n; i += ranks) t.push_back(i);
    return t;
}

// One rank's share of the passes: per tab, a RenderSession that renders this rank's tiles
// and accumulates them over the passes exactly as one process accumulates them.
class PassWorker {
   public:
    PassWorker(int rank, int ranks, const ViewJob& job)
        : rank_(rank), ranks_(ranks), scene_(job.scene), base_(job.config.settings), frame_(job.config.frame) {
        frame_.progress = false;
        frame_.depth = true;  // eye-dome lighting is applied by rank 0 to the gathered depth
    }

    // Renders the pass `cmd` (rank 0's request); returns the result and this rank's tiles
    // of the resolved frame (kFloats per pixel), or throws.
    std::pair<engine::PassResult, engine::Frame> render(const json& cmd, float* edlOut = nullptr) {
        const uint64_t view = cmd.at("view").get<uint64_t>();
        const int w = cmd.at("width").get<int>(), h = cmd.at("height").get<int>(), scale = cmd.at("scale").get<int>();
        // The page's settings messages merged, over this rank's command-line settings.
        engine::Settings s = base_;
        if (!cmd.at("settings").empty()) viewer::applySettings(cmd.at("settings"), scene_.kind(), s);
        json cam = cmd.at("camera");
        cam["type"] = "camera";
        const CameraFrame camera = viewer::parseMessage(cam.dump()).camera;
        const float edl = engine::eyeDomeStrength(scene_, s);
        if (edl > 0) s.points.edl = 0.0f;
        if (edlOut) *edlOut = edl;
        const std::string camText = cmd.at("camera").dump(), setText = cmd.at("settings").dump();
        View& v = views_[view];
        if (!v.session || v.width != w || v.height != h) {
            engine::FrameOptions fo = frame_;
            fo.width = w;
            fo.height = h;
            fo.nextTile = [tiles = v.tiles, me = rank_, step = ranks_] {
                const int t = me + tiles->next.fetch_add(1) * step;
                return t < tiles->count.load() ? t : -1;
            };
            v.session = std::make_shared<engine::RenderSession>(scene_, s, fo, camera);
            v.width = w;
            v.height = h;
        } else {
            if (camText != v.camera) v.session->setCamera(camera);
            if (setText != v.settings) v.session->setSettings(s);
        }
        v.camera = camText;
        v.settings = setText;
        v.session->setScale(scale);
        const int pw = std::max(1, w / scale), ph = std::max(1, h / scale);
        v.tiles->count = TileGrid(pw, ph, RenderOptions{}.tileSize).count();
        v.tiles->next = 0;
        const engine::PassResult r = v.session->renderPass();
        if (r.status != engine::PassResult::Status::Done) throw Error("view", "a pass was cancelled");
        return {r, v.session->frame()};
    }
    void close(uint64_t view) { views_.erase(view); }

    // This rank's tiles of `f`, kFloats per pixel.
    std::vector<float> pack(const engine::Frame& f) const {
        std::vector<float> out;
        for (int t : tilesOf(rank_, ranks_, f.width, f.height)) {
            const Region r = TileGrid(f.width, f.height, RenderOptions{}.tileSize).region(t);
            for (int y = r.y0; y < r.y1; ++y)
                for (int x = r.x0; x < r.x1; ++x) {
                    const size_t i = size_t(y) * size_t(f.width) + size_t(x);
                    out.insert(out.end(), f.rgba.data() + i * 4, f.rgba.data() + i * 4 + 4);
                    out.push_back(f.depth[i]);
                }
        }
        return out;
    }

   private:
    struct Tiles {
        std::atomic<int> next{0}, count{0};
    };
    struct View {
        std::shared_ptr<engine::RenderSession> session;
        std::shared_ptr<Tiles> tiles = std::make_shared<Tiles>();
        std::string camera, settings;  // as last applied
        int width = 0, height = 0;
    };
    int rank_, ranks_;
    engine::Scene scene_;
    engine::Settings base_;
    engine::FrameOptions frame_;
    std::map<uint64_t, View> views_;
};

// Rank 0: one pass of one tab on every rank (tabs take turns: the ranks render one pass at
// a time).
class PassLeader {
   public:
    PassLeader(int ranks, const ViewJob& job) : ranks_(ranks), kind_(job.scene.kind()), worker_(0, ranks, job) {}

    std::pair<engine::PassResult, engine::Frame> pass(const viewer::ViewerConfig::PassRequest& q) {
        std::lock_guard l(m_);
        if (quit_) throw Error("mpi", "the viewer is stopping");
        const auto t0 = std::chrono::steady_clock::now();
        const json cmd{{"cmd", "pass"},
                       {"view", q.view},
                       {"width", q.width},
                       {"height", q.height},
                       {"scale", q.scale},
                       {"camera", viewer::cameraJson(q.camera)},
                       {"settings", q.settingsPatch}};
        broadcast(cmd);
        engine::PassResult r;
        engine::Frame f;
        float edl = 0;
        const Outcome mine = attempt([&] { std::tie(r, f) = worker_.render(cmd, &edl); });
        // Every rank answers, failed or not: the ranks stay in step.
        std::string failure = mine.status ? "rank 0: " + mine.message : "";
        for (int rank = 1; rank < ranks_; ++rank) {
            const std::vector<int> head = receive<int>(rank, kReplyTag, MPI_INT, kNap);
            if (head.empty() || head[0] != 0) {
                const std::vector<char> msg = receive<char>(rank, kReplyTag, MPI_CHAR, kNap);
                if (failure.empty())
                    failure = "rank " + std::to_string(rank) + ": " + std::string(msg.begin(), msg.end());
                continue;
            }
            const std::vector<float> px = receive<float>(rank, kReplyTag, MPI_FLOAT, kNap);
            if (mine.status) continue;
            unpack(f, rank, px);
        }
        if (!failure.empty()) throw Error("mpi", failure);
        engine::applyEyeDomeLighting(f, edl);
        f.depth = {};
        r.render.ms = engine::msSince(t0);  // the whole pass: what the preview scale adapts to
        return {r, std::move(f)};
    }
    void close(uint64_t view) {
        std::lock_guard l(m_);
        if (quit_) return;
        broadcast(json{{"cmd", "close"}, {"view", view}});
        worker_.close(view);
    }
    // The other ranks exit; later passes and closes are refused here.
    void quit() {
        std::lock_guard l(m_);
        if (!quit_) broadcast(json{{"cmd", "quit"}});
        quit_ = true;
    }

   private:
    static constexpr std::chrono::microseconds kNap{50};
    void broadcast(const json& cmd) {
        const std::string text = cmd.dump();
        for (int rank = 1; rank < ranks_; ++rank)
            MPI_Send(text.data(), int(text.size()), MPI_CHAR, rank, kCommandTag, MPI_COMM_WORLD);
    }
    void unpack(engine::Frame& f, int rank, const std::vector<float>& px) const {
        const float* p = px.data();
        const float* end = px.data() + px.size();
        for (int t : tilesOf(rank, ranks_, f.width, f.height)) {
            const Region r = TileGrid(f.width, f.height, RenderOptions{}.tileSize).region(t);
            for (int y = r.y0; y < r.y1; ++y)
                for (int x = r.x0; x < r.x1 && p + kFloats <= end; ++x, p += kFloats) {
                    const size_t i = size_t(y) * size_t(f.width) + size_t(x);
                    std::copy(p, p + 4, f.rgba.data() + i * 4);
                    f.depth[i] = p[4];
                }
        }
    }
    std::mutex m_;
    bool quit_ = false;
    int ranks_;
    engine::SceneKind kind_;
    PassWorker worker_;
};

// The other ranks: render the passes rank 0 sends until it says quit.
void follow(PassWorker& worker) {
    // Ctrl-C reaches every rank: rank 0 stops its server and then tells the others.
    std::signal(SIGINT, SIG_IGN);
    std::signal(SIGTERM, SIG_IGN);
    for (;;) {
        // Idle between passes: a nap of 1 ms costs nothing next to a pass.
        const std::vector<char> text = receive<char>(0, kCommandTag, MPI_CHAR, std::chrono::milliseconds(1));
        const json cmd = json::parse(std::string(text.begin(), text.end()));
        const std::string what = cmd.at("cmd").get<std::string>();
        if (what == "quit") return;
        if (what == "close") {
            worker.close(cmd.at("view").get<uint64_t>());
            continue;
        }
        engine::Frame f;
        const Outcome o = attempt([&] { f = worker.render(cmd).second; });
        int head = o.status;
        MPI_Send(&head, 1, MPI_INT, 0, kReplyTag, MPI_COMM_WORLD);
        if (o.status) {
            MPI_Send(o.message.data(), int(o.message.size()), MPI_CHAR, 0, kReplyTag, MPI_COMM_WORLD);
            continue;
        }
        const std::vector<float> px = worker.pack(f);
        MPI_Send(px.data(), int(px.size()), MPI_FLOAT, 0, kReplyTag, MPI_COMM_WORLD);
    }
}

}  // namespace

int runMpiView(const std::function<ViewJob(bool root)>& prepare, const std::function<void(ViewJob&)>& serve) {
    mpi::Mpi mpi;
    const bool root = mpi.rank == 0;
    if (int st =
            mpi.agree(mpi.serialized ? Outcome{} : Outcome{1, "the MPI library does not offer MPI_THREAD_SERIALIZED"}))
        return st;
    ViewJob job;
    if (int st = mpi.agree(attempt([&] { job = prepare(root); }))) return st;
    if (!root) {
        PassWorker worker(mpi.rank, mpi.size, job);
        follow(worker);
        return 0;
    }
    PassLeader leader(mpi.size, job);
    job.config.renderPass = [&leader](const viewer::ViewerConfig::PassRequest& q) { return leader.pass(q); };
    job.config.closeView = [&leader](uint64_t view) { leader.close(view); };
    if (!job.quiet)
        std::fprintf(stderr, "rtfact: mpi: %d ranks serve the viewer (image-parallel, every rank holds the scene)\n",
                     mpi.size);
    const Outcome served = attempt([&] { serve(job); });
    leader.quit();
    if (served.status) std::fprintf(stderr, "rtfact: error: rank 0: %s\n", served.message.c_str());
    return served.status;
}

}  // namespace rtfact::app
