#include "apps/view/access_token.h"

#include <cstdint>
#include <random>

namespace rtfact::viewer {

std::string makeAccessToken() {
    std::random_device rd;  // /dev/urandom on Linux
    static const char* hex = "0123456789abcdef";
    std::string t;
    for (int i = 0; i < 4; ++i) {
        const uint32_t v = rd();
        for (int k = 0; k < 8; ++k) t += hex[(v >> (4 * k)) & 15u];
    }
    return t;
}

bool tokenMatches(std::string_view given, std::string_view expected) {
    if (given.size() != expected.size() || expected.empty()) return false;
    unsigned diff = 0;
    for (size_t i = 0; i < given.size(); ++i) diff |= unsigned(uint8_t(given[i]) ^ uint8_t(expected[i]));
    return diff == 0;
}

std::string_view pathOfTarget(std::string_view target) { return target.substr(0, target.find('?')); }

std::string tokenOfTarget(std::string_view target) {
    const size_t q = target.find('?');
    if (q == std::string_view::npos) return {};
    std::string_view query = target.substr(q + 1);
    while (!query.empty()) {
        const size_t amp = query.find('&');
        const std::string_view pair = query.substr(0, amp);
        if (pair.substr(0, 6) == "token=") return std::string(pair.substr(6));
        if (amp == std::string_view::npos) break;
        query = query.substr(amp + 1);
    }
    return {};
}

}  // namespace rtfact::viewer
