// A rendered frame (linear RGBA floats, background composited) as the bytes a browser
// shows: JPEG through libjpeg-turbo for the live frames, PNG (lossless) for screenshots
// and lossless sessions. Both store sRGB like the CLI's image writer.
#pragma once
#include <cstdint>
#include <vector>

#include "engine/render_session.h"

namespace rtfact::viewer {

// 8-bit sRGB RGB, rows top to bottom.
std::vector<uint8_t> toSrgb8(const engine::Frame& frame);
// quality 1..100; throws rtfact::Error("jpeg", ...) when libjpeg-turbo fails.
std::vector<uint8_t> encodeJpeg(const engine::Frame& frame, int quality);
// Through the CLI's image writer (core/render/image_io), so that a screenshot has the
// very bytes `rtfact ... -o x.png` writes.
std::vector<uint8_t> encodePng(const engine::Frame& frame);

}  // namespace rtfact::viewer
