// The text forms of settings every front end accepts (CLI options, Python keywords, the
// viewer's messages): one parser each, throwing UsageError(option, ...) with the message
// the user sees. `option` names the setting as the front end spells it ("--light", "light").
#pragma once
#include <string>

#include "core/math/vec3f.h"
#include "engine/settings.h"

namespace rtfact::engine {

// "x,y,z": three finite numbers.
Vec3f parseVec3Text(const std::string& text, const std::string& option);
// "point:x,y,z" or "dir:x,y,z".
LightSpec parseLightText(const std::string& text, const std::string& option);
// lambert[:r,g,b] | mirror[:r,g,b] | glass[:ior]: the replacement material.
surfaces::MeshMaterial parseMaterialText(const std::string& text, const std::string& option);
// "axis:lo:hi" (axis x|y|z, 0 <= lo < hi <= 1): sets that axis's clip range in `s`.
void applyClipText(const std::string& text, VolumeSettings& s, const std::string& option);
// Sets the clip range of one axis ("x", "y" or "z") after the same checks.
void applyClip(const std::string& axis, float lo, float hi, VolumeSettings& s, const std::string& option);

}  // namespace rtfact::engine
