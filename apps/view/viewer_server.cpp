#include "apps/view/viewer_server.h"

#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <deque>
#include <mutex>
#include <thread>

#include "apps/view/access_token.h"
#include "apps/view/web_assets.h"
#include "core/util/error.h"

namespace rtfact::viewer {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

struct ViewerServer::Impl {
    engine::Scene scene;
    ViewerConfig config;
    ServerOptions options;
    net::io_context ioc{1};
    tcp::acceptor acceptor{ioc};
    std::optional<net::signal_set> signals;
    std::thread thread;
    mutable std::mutex m;
    std::vector<std::shared_ptr<ClientSession>> sessions;  // joined when finished

    void accept();
    void add(std::shared_ptr<ClientSession> s) {
        std::lock_guard l(m);
        // Reap the sessions of closed connections (their threads have ended or end soon).
        for (auto it = sessions.begin(); it != sessions.end();) {
            if ((*it)->finished()) {
                (*it)->join();
                it = sessions.erase(it);
            } else {
                ++it;
            }
        }
        sessions.push_back(std::move(s));
    }
};

namespace {

std::string_view sv(beast::string_view s) { return {s.data(), s.size()}; }

// One WebSocket client: reads its messages into its ClientSession and writes what the
// session sends, one write at a time, in order (all on the network thread).
class WsConnection : public std::enable_shared_from_this<WsConnection> {
   public:
    WsConnection(tcp::socket&& socket, ViewerServer::Impl& server) : ws_(std::move(socket)), server_(server) {}

    void run(http::request<http::string_body> req) {
        // Frames are a small text message and the image: without this, Nagle's algorithm
        // holds the second behind the client's delayed ACK (tens of ms per frame).
        beast::error_code ignored;
        beast::get_lowest_layer(ws_).socket().set_option(tcp::no_delay(true), ignored);
        ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
        // Larger messages than this close the connection (1009); up to it, the protocol's
        // own limit (kMaxMessageBytes) answers with an error message.
        ws_.read_message_max(1 << 20);
        ws_.async_accept(req, beast::bind_front_handler(&WsConnection::onAccept, shared_from_this()));
    }

    ~WsConnection() {
        if (session_) session_->stop();
    }

    void send(bool binary, std::string text, std::vector<uint8_t> bytes) {
        if (closed_) return;
        queue_.push_back({binary, std::move(text), std::move(bytes)});
        if (!writing_) write();
    }

   private:
    struct Out {
        bool binary;
        std::string text;
        std::vector<uint8_t> bytes;
    };

    void onAccept(beast::error_code ec) {
        if (ec) return;
        std::weak_ptr<WsConnection> weak = shared_from_this();
        auto ex = ws_.get_executor();
        // The session's threads post to the network thread; a closed connection drops them.
        ClientSession::Output out{[weak, ex](std::string text) {
                                      net::post(ex, [weak, t = std::move(text)]() mutable {
                                          if (auto c = weak.lock()) c->send(false, std::move(t), {});
                                      });
                                  },
                                  [weak, ex](std::string meta, std::vector<uint8_t> bytes) {
                                      net::post(ex, [weak, t = std::move(meta), b = std::move(bytes)]() mutable {
                                          if (auto c = weak.lock()) {
                                              c->send(false, std::move(t), {});
                                              c->send(true, {}, std::move(b));
                                          }
                                      });
                                  }};
        try {
            session_ = std::make_shared<ClientSession>(server_.scene, server_.config, std::move(out));
        } catch (const Error& e) {
            send(false, errorJson(e.message()).dump(), {});
            return;
        }
        server_.add(session_);
        send(false, session_->hello(), {});
        read();
    }

    void read() { ws_.async_read(buffer_, beast::bind_front_handler(&WsConnection::onRead, shared_from_this())); }

    void onRead(beast::error_code ec, size_t) {
        if (ec) {
            close();
            return;
        }
        if (!ws_.got_text())
            send(false, errorJson("message: binary messages are not accepted").dump(), {});
        else
            session_->handle(sv(beast::string_view(static_cast<const char*>(buffer_.data().data()), buffer_.size())));
        buffer_.consume(buffer_.size());
        read();
    }

    void write() {
        writing_ = true;
        const Out& o = queue_.front();
        ws_.binary(o.binary);
        auto done = beast::bind_front_handler(&WsConnection::onWrite, shared_from_this());
        if (o.binary)
            ws_.async_write(net::buffer(o.bytes), std::move(done));
        else
            ws_.async_write(net::buffer(o.text), std::move(done));
    }

    void onWrite(beast::error_code ec, size_t) {
        queue_.pop_front();
        if (ec) close();
        if (closed_ || queue_.empty()) {
            writing_ = false;
            if (closed_) queue_.clear();
            return;
        }
        write();
    }

    // The client is gone: its session stops (the pass in flight is cancelled). A write in
    // flight still owns the queue's front; onWrite empties the queue after it.
    void close() {
        closed_ = true;
        if (!writing_) queue_.clear();
        if (session_) session_->stop();
    }

    websocket::stream<beast::tcp_stream> ws_;
    beast::flat_buffer buffer_;
    ViewerServer::Impl& server_;
    std::shared_ptr<ClientSession> session_;
    std::deque<Out> queue_;
    bool writing_ = false, closed_ = false;
};

// One HTTP connection: the page's files for requests with the token, 401 without it,
// the upgrade to a WebSocket session on /ws.
class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
   public:
    HttpConnection(tcp::socket&& socket, ViewerServer::Impl& server) : stream_(std::move(socket)), server_(server) {}
    void run() { read(); }

   private:
    void read() {
        parser_.emplace();
        parser_->header_limit(16 * 1024);
        parser_->body_limit(16 * 1024);
        stream_.expires_after(std::chrono::seconds(30));
        http::async_read(stream_, buffer_, *parser_,
                         beast::bind_front_handler(&HttpConnection::onRead, shared_from_this()));
    }

    void onRead(beast::error_code ec, size_t) {
        if (ec) {
            // End of stream, timeout, or a request over the limits: close.
            beast::error_code ignored;
            stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
            return;
        }
        http::request<http::string_body> req = parser_->release();
        const std::string_view target = sv(req.target());
        const bool tokenOk = tokenMatches(tokenOfTarget(target), server_.options.token);
        if (websocket::is_upgrade(req) && tokenOk && pathOfTarget(target) == "/ws") {
            stream_.expires_never();
            std::make_shared<WsConnection>(stream_.release_socket(), server_)->run(std::move(req));
            return;
        }
        respond(req, tokenOk);
    }

    void respond(const http::request<http::string_body>& req, bool tokenOk) {
        auto res = std::make_shared<http::response<http::string_body>>();
        res->version(req.version());
        res->keep_alive(req.keep_alive());
        res->set(http::field::server, "rtfact-view");
        res->set(http::field::cache_control, "no-store");
        res->set("X-Content-Type-Options", "nosniff");
        res->set("Referrer-Policy", "no-referrer");  // the token is in the URL
        const WebAsset* asset = findWebAsset(pathOfTarget(sv(req.target())));
        auto text = [&](http::status s, std::string body) {
            res->result(s);
            res->set(http::field::content_type, "text/plain; charset=utf-8");
            res->body() = std::move(body);
        };
        if (req.method() != http::verb::get && req.method() != http::verb::head) {
            text(http::status::method_not_allowed, "rtfact view: only GET\n");
        } else if (!tokenOk) {
            text(http::status::unauthorized, "rtfact view: missing or wrong token (use the URL rtfact printed)\n");
        } else if (!asset || websocket::is_upgrade(req)) {
            text(http::status::not_found, "rtfact view: not found\n");
        } else {
            res->result(http::status::ok);
            res->set(http::field::content_type, std::string(asset->contentType));
            std::string body(asset->body);
            // The page's links carry the token (every request must).
            for (size_t p; (p = body.find("__TOKEN__")) != std::string::npos;)
                body.replace(p, 9, server_.options.token);
            res->body() = std::move(body);
        }
        res->prepare_payload();
        if (req.method() == http::verb::head) res->body().clear();
        http::async_write(stream_, *res, [self = shared_from_this(), res](beast::error_code ec, size_t) {
            if (ec) return;
            if (!res->keep_alive()) {
                beast::error_code ignored;
                self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
                return;
            }
            self->read();
        });
    }

    beast::tcp_stream stream_;
    beast::flat_buffer buffer_;
    std::optional<http::request_parser<http::string_body>> parser_;
    ViewerServer::Impl& server_;
};

}  // namespace

void ViewerServer::Impl::accept() {
    acceptor.async_accept(ioc, [this](beast::error_code ec, tcp::socket socket) {
        if (ec == net::error::operation_aborted || !acceptor.is_open()) return;
        if (!ec) std::make_shared<HttpConnection>(std::move(socket), *this)->run();
        accept();
    });
}

ViewerServer::ViewerServer(engine::Scene scene, ViewerConfig config, ServerOptions options)
    : impl_(std::make_unique<Impl>()) {
    Impl& s = *impl_;
    s.scene = std::move(scene);
    s.config = std::move(config);
    s.options = std::move(options);
    if (s.options.token.empty()) s.options.token = makeAccessToken();
    beast::error_code ec;
    const net::ip::address addr = net::ip::make_address(s.options.bind, ec);
    if (ec) throw Error("--bind", "not an IP address: '" + s.options.bind + "'");
    if (s.options.port < 0 || s.options.port > 65535)
        throw Error("--port", "must be 0..65535, got " + std::to_string(s.options.port));
    const tcp::endpoint ep(addr, static_cast<unsigned short>(s.options.port));
    const std::string where = s.options.bind + ":" + std::to_string(s.options.port);
    s.acceptor.open(ep.protocol(), ec);
    if (!ec) s.acceptor.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) s.acceptor.bind(ep, ec);
    if (!ec) s.acceptor.listen(net::socket_base::max_listen_connections, ec);
    if (ec) throw Error("--port", "cannot listen on " + where + ": " + ec.message());
    s.accept();
}

ViewerServer::~ViewerServer() { stop(); }

int ViewerServer::port() const { return impl_->acceptor.local_endpoint().port(); }
const std::string& ViewerServer::token() const { return impl_->options.token; }

std::string ViewerServer::url() const {
    std::string host = impl_->options.bind;
    if (host == "0.0.0.0") host = "127.0.0.1";
    if (host == "::") host = "[::1]";
    if (host.find(':') != std::string::npos && host.front() != '[') host = "[" + host + "]";
    return "http://" + host + ":" + std::to_string(port()) + "/?token=" + impl_->options.token;
}

void ViewerServer::start() {
    impl_->thread = std::thread([this] { impl_->ioc.run(); });
}

void ViewerServer::run() {
    // Ctrl-C ends the server cleanly (sessions stopped, sockets closed).
    impl_->signals.emplace(impl_->ioc, SIGINT, SIGTERM);
    impl_->signals->async_wait([this](beast::error_code ec, int) {
        if (!ec) impl_->ioc.stop();
    });
    impl_->ioc.run();
}

void ViewerServer::stop() {
    Impl& s = *impl_;
    s.ioc.stop();
    if (s.thread.joinable()) s.thread.join();
    std::vector<std::shared_ptr<ClientSession>> all;
    {
        std::lock_guard l(s.m);
        all.swap(s.sessions);
    }
    for (auto& c : all) c->stop();
    for (auto& c : all) c->join();
}

int ViewerServer::sessions() const {
    std::lock_guard l(impl_->m);
    int n = 0;
    for (const auto& c : impl_->sessions) n += c->finished() ? 0 : 1;
    return n;
}

}  // namespace rtfact::viewer
