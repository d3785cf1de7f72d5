// The secret in the viewer's URL: every HTTP and WebSocket request must carry it, so
// that other users of the machine (the server listens on a TCP port) cannot watch or
// steer the view.
#pragma once
#include <string>
#include <string_view>

namespace rtfact::viewer {

// 32 hex digits (128 bits) from the system's random source.
std::string makeAccessToken();
// Compares in time independent of where the strings differ.
bool tokenMatches(std::string_view given, std::string_view expected);
// The value of `token` in a request target "/path?a=b&token=...": "" when absent.
std::string tokenOfTarget(std::string_view target);
// The path part of a request target (before '?').
std::string_view pathOfTarget(std::string_view target);

}  // namespace rtfact::viewer
