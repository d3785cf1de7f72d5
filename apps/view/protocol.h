// The viewer's WebSocket protocol: JSON text messages from the page, validated here
// (size, schema, ranges) before anything is changed, and the JSON the server sends.
// A bad message throws rtfact::Error("message", ...) and changes nothing.
//
// Page -> server: {"type": "camera", "eye": [x,y,z], "at": [..], "up": [..], "fov": f,
// "moving": bool} | {"type": "ack", "frame": id} | {"type": "resize", "width": w,
// "height": h} | {"type": "settings", "points"|"volume"|"mesh": {...}} | {"type": "fit"}
// | {"type": "reset"} | {"type": "screenshot"} | {"type": "format", "lossless": bool,
// "quality": 1..100}.
// Server -> page: "hello" (scene, camera, settings, choices, histogram), "frame" (meta
// data, then the image as one binary message), "camera", "transfer", "screenshot" (then
// the PNG), "error".
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "core/render/pinhole_camera.h"
#include "engine/histogram.h"
#include "engine/scene.h"
#include "engine/settings.h"

namespace rtfact::viewer {

inline constexpr size_t kMaxMessageBytes = 64 * 1024;
inline constexpr int kMaxImageSide = 4096;

struct ClientMessage {
    enum class Type { Camera, Ack, Resize, Settings, Fit, Reset, Screenshot, Format } type = Type::Ack;
    CameraFrame camera;
    bool moving = false;
    uint64_t frame = 0;
    int width = 0, height = 0;
    nlohmann::json settings;  // the domain's patch (validated by applySettings)
    bool lossless = false;
    int quality = 85;
};

// Parses and validates one text message (throws rtfact::Error("message", ...)).
ClientMessage parseMessage(std::string_view text);

// Applies a settings patch of the scene's kind to `s` (all or nothing: on error `s` is
// unchanged). Throws rtfact::Error("message", ...).
void applySettings(const nlohmann::json& patch, engine::SceneKind kind, engine::Settings& s);

nlohmann::json cameraJson(const CameraFrame& c);
// The settings of the scene's kind, in the schema applySettings reads.
nlohmann::json settingsJson(const engine::Settings& s, engine::SceneKind kind);
// What the page offers for the kind (integrators, modes, presets ...).
nlohmann::json choicesJson(engine::SceneKind kind);
// Histogram (counts per bin over [lo, hi]), the TF in our JSON format and its window.
nlohmann::json transferJson(const engine::VolumeTransferInfo& t);
nlohmann::json errorJson(const std::string& message);

}  // namespace rtfact::viewer
