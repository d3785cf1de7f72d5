// ViewerServer: the HTTP + WebSocket server of `rtfact view` (Boost.Beast). It serves
// the built-in page (and nothing else) to requests carrying the access token, and gives
// every WebSocket connection its own ClientSession over the one shared scene. One network
// thread runs all connections; rendering happens on the sessions' threads.
#pragma once
#include <memory>
#include <string>

#include "apps/view/client_session.h"
#include "engine/scene.h"

namespace rtfact::viewer {

struct ServerOptions {
    std::string bind = "127.0.0.1";
    int port = 0;       // 0: a free port
    std::string token;  // empty: a random one
};

class ViewerServer {
   public:
    // Binds and listens; throws rtfact::Error("--bind"/"--port", ...) when it cannot.
    ViewerServer(engine::Scene scene, ViewerConfig config, ServerOptions options);
    ~ViewerServer();
    ViewerServer(const ViewerServer&) = delete;
    ViewerServer& operator=(const ViewerServer&) = delete;

    int port() const;
    const std::string& token() const;
    // http://HOST:PORT/?token=... (HOST: the bind address, 127.0.0.1 for 0.0.0.0).
    std::string url() const;
    // Serves on a background thread / on this thread until stop().
    void start();
    void run();
    // Closes the listener and every connection, stops and joins every session.
    void stop();
    // WebSocket sessions open now.
    int sessions() const;

    struct Impl;  // opaque (Boost.Beast stays out of this header)

   private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace rtfact::viewer
