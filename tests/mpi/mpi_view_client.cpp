// mpi_view_client PORT TOKEN PREFIX: drives `rtfact view` like a page, without a browser
// (apps/view/viewer_client.h), and writes the fully accumulated frames of three views as
// lossless PNGs: PREFIX-home.png (the initial camera), PREFIX-moved.png (another camera,
// reached through a drag of preview frames) and PREFIX-normal.png (a settings change:
// colour by normal). tests/mpi compares the frames an mpirun-served viewer streams with a
// single-process viewer's. MPI_VIEW_CLIENT_TRACE=1 prints every frame's meta data.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <utility>  // before Boost.Asio (its awaitable.hpp uses std::exchange)

#include "apps/view/viewer_client.h"

using namespace rtfact::viewer::client;

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: mpi_view_client PORT TOKEN PREFIX\n");
        return 2;
    }
    try {
        WsClient ws(std::atoi(argv[1]), argv[2]);
        const json hello = ws.until("hello");
        const int maxSamples = hello["maxSamples"].get<int>();
        ws.send(json{{"type", "format"}, {"lossless", true}, {"quality", 85}});
        // The still frame of the current view: full resolution, every sample, PNG.
        auto still = [&](const std::string& name, const json& camera) {
            const FrameMsg f = ws.frame([&](const json& m) {
                if (std::getenv("MPI_VIEW_CLIENT_TRACE")) std::fprintf(stderr, "%s\n", m.dump().c_str());
                return m["samples"] == maxSamples && m["scale"] == 1 && m["format"] == "png" &&
                       (camera.is_null() || m["camera"]["eye"] == camera["eye"]);
            });
            std::ofstream(std::string(argv[3]) + "-" + name + ".png", std::ios::binary) << f.bytes;
            std::printf("%s: %s\n", name.c_str(), f.meta.dump().c_str());
        };
        still("home", nullptr);
        // A drag (preview frames at a reduced scale), then still at the new camera.
        json cam = hello["camera"];
        cam["type"] = "camera";
        for (int step = 1; step <= 3; ++step) {
            for (int k = 0; k < 3; ++k)
                // floats, so that the frames' camera (floats) compares equal
                cam["eye"][k] = float(cam["at"][k].get<double>() +
                                      (cam["eye"][k].get<double>() - cam["at"][k].get<double>()) * 1.1);
            cam["moving"] = step < 3;
            ws.send(cam);
        }
        still("moved", cam);
        ws.send(json{{"type", "settings"}, {"points", {{"color", "normal"}}}});
        still("normal", cam);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mpi_view_client: %s\n", e.what());
        return 1;
    }
}
