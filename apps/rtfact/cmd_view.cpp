// `rtfact view [points|volume|mesh] FILE...`: the interactive viewer. Loads the data like
// the render commands (same options, same progress output), then serves the page and a
// progressive session per browser tab (apps/view). Without a domain word the kind comes
// from the file and the domain's defaults are used; with it, every option of that render
// command applies (CLI11 cannot register e.g. --integrator of points and mesh on one
// command, so each domain is a subcommand of `view`).
#include <arpa/inet.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <thread>

#include "apps/rtfact/commands.h"
#include "apps/rtfact/common_options.h"
#include "apps/rtfact/mesh_options.h"
#include "apps/rtfact/mpi_view.h"
#include "apps/rtfact/point_options.h"
#include "apps/rtfact/volume_options.h"
#include "apps/view/viewer_server.h"
#ifdef RTFACT_MPI
#include "apps/rtfact/mpi_render.h"
#endif
#include "engine/render_session.h"

extern char** environ;

namespace rtfact::app {

namespace {

struct ViewOptions {
    int port = 0;
    std::string bind = "127.0.0.1";
    bool noBrowser = false;
    int maxSamples = 64;
    float frameMs = 40.0f;
    int quality = 85;

    void addTo(CLI::App& cmd) {
        cmd.add_option("--port", port, "TCP port (0: a free one)")->capture_default_str()->check(CLI::Range(0, 65535));
        cmd.add_option("--bind", bind, "Address to listen on (0.0.0.0: every interface; mind the token)")
            ->capture_default_str();
        cmd.add_flag("--no-browser", noBrowser, "Do not open a browser");
        cmd.add_option("--max-samples", maxSamples, "Samples per pixel accumulated while the view is still")
            ->capture_default_str()
            ->check(CLI::Range(1, 65536));
        cmd.add_option("--frame-ms", frameMs, "Frame-time target of the preview while moving")
            ->capture_default_str()
            ->check(finiteRange(5.0, 2000.0));
        cmd.add_option("--quality", quality, "JPEG quality of the live frames")
            ->capture_default_str()
            ->check(CLI::Range(1, 100));
    }
};

// xdg-open when there is a display and the tool exists; any failure is silent (the URL
// is printed anyway).
void openBrowser(const std::string& url) {
    if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY")) return;
    posix_spawn_file_actions_t fa;
    if (posix_spawn_file_actions_init(&fa) != 0) return;
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);
    std::string prog = "xdg-open", arg = url;
    char* argv[] = {prog.data(), arg.data(), nullptr};
    pid_t pid = 0;
    if (posix_spawnp(&pid, "xdg-open", &fa, nullptr, argv, environ) == 0)
        std::thread([pid] { waitpid(pid, nullptr, 0); }).detach();
    posix_spawn_file_actions_destroy(&fa);
}

// Options, settings, the scene and the viewer's configuration (`writer`: prints the
// scene's warnings; under MPI only rank 0 does).
ViewJob prepareView(CommonOptions& c, const ViewOptions& v, const std::function<engine::Settings()>& settings,
                    const std::function<engine::Scene()>& open, bool defaultPointPacket, bool writer) {
    c.finalize();
    // A bad address is bad usage, found before the data are loaded.
    in6_addr probe{};
    if (inet_pton(AF_INET, v.bind.c_str(), &probe) != 1 && inet_pton(AF_INET6, v.bind.c_str(), &probe) != 1)
        throw CLI::ValidationError("--bind", "expected an IPv4 or IPv6 address, got '" + v.bind + "'");
    engine::Settings s = settings();
    ViewJob job;
    job.scene = open();
    const engine::Scene& scene = job.scene;
    if (writer && !c.quiet)
        for (const std::string& w : scene.warnings()) std::fprintf(stderr, "rtfact: warning: %s\n", w.c_str());
    const engine::DefaultView view = scene.defaultView(s);
    viewer::ViewerConfig& cfg = job.config;
    cfg.settings = s;
    cfg.home = c.frame(view.focus, view.viewDir, view.up);
    cfg.frame.width = c.width;
    cfg.frame.height = c.height;
    cfg.frame.threads = c.threads;
    cfg.frame.packet = defaultPointPacket && scene.kind() == engine::SceneKind::Points
                           ? engine::defaultPacketSize(scene.kind())
                           : c.packet;
    cfg.maxSamples = v.maxSamples;
    cfg.frameMs = v.frameMs;
    cfg.jpegQuality = v.quality;
    cfg.screenshotSpp = c.spp;
    job.quiet = c.quiet;
    return job;
}

void runServer(ViewJob& job, const ViewOptions& v) {
    viewer::ServerOptions so;
    so.bind = v.bind;
    so.port = v.port;
    viewer::ViewerServer server(job.scene, job.config, so);
    std::printf("rtfact: viewing at %s\n", server.url().c_str());
    std::fflush(stdout);
    if (!v.noBrowser) openBrowser(server.url());
    server.run();
}

int serve(CommonOptions& c, const ViewOptions& v, const std::function<engine::Settings()>& settings,
          const std::function<engine::Scene()>& open, bool defaultPointPacket) {
#ifdef RTFACT_MPI
    // Under mpirun: rank 0 serves, every rank renders (apps/rtfact/mpi_view.h).
    if (mpiLaunched())
        return runMpiView(
            [&](bool root) {
                if (!root) c.quiet = true;
                return prepareView(c, v, settings, open, defaultPointPacket, root);
            },
            [&](ViewJob& job) { runServer(job, v); });
#endif
    ViewJob job = prepareView(c, v, settings, open, defaultPointPacket, true);
    runServer(job, v);
    return 0;
}

}  // namespace

void addViewCommand(CLI::App& app, CommandList& list) {
    struct Opts {
        CommonOptions common;
        ViewOptions view;
        std::vector<std::string> files;
        std::vector<std::string> pointFiles, volumeFile, meshFiles;
        PointOptions points;
        VolumeOptions volume;
        MeshOptions mesh;
    };
    auto o = std::make_shared<Opts>();
    CLI::App* cmd = app.add_subcommand(
        "view",
        "Interactive viewer in the browser: `view FILE...` (kind from the file) or `view points|volume|mesh "
        "FILE... [that command's options]`");
    o->common.addTo(*cmd, "screenshot.png");
    o->view.addTo(*cmd);
    cmd->add_option("FILE", o->files, "Data file(s): a volume, meshes or a point cloud");

    CLI::App* pts = cmd->add_subcommand("points", "View a point cloud with the options of `rtfact points`");
    pts->fallthrough();
    pts->add_option("FILE", o->pointFiles, "Point cloud file (.ply .pcd .xyz .pts)")->required()->expected(1);
    o->points.addTo(*pts);
    CLI::App* vol = cmd->add_subcommand("volume", "View a volume with the options of `rtfact volume`");
    vol->fallthrough();
    vol->add_option("FILE", o->volumeFile, "Volume file or DICOM directory")->required()->expected(1);
    o->volume.addTo(*vol);
    CLI::App* msh = cmd->add_subcommand("mesh", "View meshes with the options of `rtfact mesh`");
    msh->fallthrough();
    msh->add_option("FILE", o->meshFiles, "Mesh file(s) (.ply .obj ...)")->required();
    o->mesh.addTo(*msh);
    cmd->require_subcommand(0, 1);

    list.push_back({cmd, [o, cmd, pts, vol, msh] {
                        CommonOptions& c = o->common;
                        // --packet not given: each kind's measured default, as its render command has.
                        const bool defaultPacket = cmd->count("--packet") == 0;
                        auto opts = [&](engine::SceneKind kind) {
                            engine::OpenOptions oo;
                            oo.kind = kind;
                            oo.progress = !c.quiet;
                            oo.keepSource = true;  // settings from the page may rebuild
                            return oo;
                        };
                        if (pts->parsed())
                            return serve(
                                c, o->view, [&] { return o->points.toSettings(); },
                                [&] { return engine::open(o->pointFiles, opts(engine::SceneKind::Points)); },
                                defaultPacket);
                        if (vol->parsed())
                            return serve(
                                c, o->view, [&] { return o->volume.toSettings(); },
                                [&] {
                                    engine::OpenOptions oo = o->volume.openOptions(!c.quiet);
                                    oo.keepSource = true;
                                    return engine::open(o->volumeFile, oo);
                                },
                                false);
                        if (msh->parsed())
                            return serve(
                                c, o->view, [&] { return o->mesh.toSettings(); },
                                [&] { return engine::open(o->meshFiles, opts(engine::SceneKind::Mesh)); }, false);
                        if (o->files.empty())
                            throw CLI::ValidationError("view", "give FILE... or points|volume|mesh FILE...");
                        return serve(
                            c, o->view, [] { return engine::Settings{}; },
                            [&] {
                                engine::OpenOptions oo;
                                oo.progress = !c.quiet;
                                return engine::open(o->files, oo);
                            },
                            defaultPacket);
                    }});
}

}  // namespace rtfact::app
