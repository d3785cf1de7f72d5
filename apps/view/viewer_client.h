// ViewerClient: a synchronous Boost.Beast client of the viewer (the scripted client of the
// tests and of `rtfact-bench view`): HTTP GET,
// and a WebSocket session that reads JSON messages and frames (meta data + bytes).
#pragma once
#include <sys/socket.h>
#include <sys/time.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

namespace rtfact::viewer::client {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;

// A read that waits longer than this fails (a hung server fails the test, not the run).
inline void receiveTimeout(tcp::socket& s, int seconds) {
    timeval tv{seconds, 0};
    ::setsockopt(s.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
}

struct HttpReply {
    int status = 0;
    std::string body;
};

inline HttpReply httpGet(int port, const std::string& target) {
    net::io_context ioc;
    tcp::socket s(ioc);
    s.connect({net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)});
    receiveTimeout(s, 60);
    http::request<http::empty_body> req{http::verb::get, target, 11};
    req.set(http::field::host, "127.0.0.1");
    http::write(s, req);
    beast::flat_buffer b;
    http::response<http::string_body> res;
    http::read(s, b, res);
    return {int(res.result_int()), res.body()};
}

struct Message {
    bool text = true;
    std::string data;
    json j;
};

struct FrameMsg {
    json meta;
    std::string bytes;
};

class WsClient {
   public:
    // Throws boost::system::system_error when the handshake is refused.
    WsClient(int port, const std::string& token) : ws_(ioc_) {
        ws_.next_layer().connect({net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)});
        receiveTimeout(ws_.next_layer(), 120);
        ws_.next_layer().set_option(tcp::no_delay(true));
        ws_.read_message_max(64u << 20);
        ws_.handshake("127.0.0.1:" + std::to_string(port), "/ws?token=" + token);
    }
    Message read() {
        beast::flat_buffer b;
        ws_.read(b);
        Message m;
        m.text = ws_.got_text();
        m.data = beast::buffers_to_string(b.data());
        if (m.text) m.j = json::parse(m.data);
        return m;
    }
    void send(const std::string& text) {
        ws_.text(true);
        ws_.write(net::buffer(text));
    }
    void send(const char* text) { send(std::string(text)); }
    void send(const json& j) { send(j.dump()); }
    void sendBinary(const std::string& bytes) {
        ws_.binary(true);
        ws_.write(net::buffer(bytes));
    }
    // Reads until a text message of `type` (frames on the way are acknowledged).
    json until(const std::string& type) {
        for (;;) {
            Message m = read();
            if (!m.text) continue;
            if (m.j["type"] == type) return m.j;
            if (m.j["type"] == "frame") ack(m.j);
        }
    }
    // The next frame (or screenshot) whose meta data satisfies `want`; acknowledges frames.
    FrameMsg frame(const std::function<bool(const json&)>& want = nullptr, const std::string& type = "frame",
                   bool acknowledge = true) {
        for (;;) {
            Message m = read();
            if (!m.text || (m.j["type"] != "frame" && m.j["type"] != "screenshot")) continue;
            Message bytes = read();
            if (bytes.text) throw std::runtime_error("expected a binary message after " + m.data);
            if (m.j["type"] == "frame" && acknowledge) ack(m.j);
            if (m.j["type"] == type && (!want || want(m.j))) return {m.j, bytes.data};
        }
    }
    void ack(const json& meta) { send(json{{"type", "ack"}, {"frame", meta["id"]}}); }
    // Drops the TCP connection without a WebSocket close (a vanished client).
    void drop() {
        beast::error_code ec;
        ws_.next_layer().close(ec);
    }

   private:
    net::io_context ioc_;
    websocket::stream<tcp::socket> ws_;
};

}  // namespace rtfact::viewer::client
