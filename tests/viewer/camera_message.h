// The page's camera message for a camera (the viewer tests' sender side).
#pragma once
#include "apps/view/protocol.h"

namespace rtfact::viewer {

inline nlohmann::json cameraMessage(const CameraFrame& c, bool moving = false) {
    nlohmann::json j = cameraJson(c);
    j["type"] = "camera";
    j["moving"] = moving;
    return j;
}

}  // namespace rtfact::viewer
