// libFuzzer harness: the CLI's own parsers of sizes (WxH) and vectors (x,y,z).
// Validation errors are the expected outcome for junk; crashes, UB or other exceptions
// are bugs.
#include <cstddef>
#include <cstdint>
#include <string>

#include "apps/rtfact/common_options.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const auto [w, h] = rtfact::app::parseSize(text);
        if (w < 1 || h < 1 || w > 16384 || h > 16384) __builtin_trap();
    } catch (const CLI::ValidationError&) {
    }
    try {
        const rtfact::Vec3f v = rtfact::app::parseVec3(text, "--eye");
        if (!rtfact::isFinite(v)) __builtin_trap();
    } catch (const CLI::ValidationError&) {
    }
    return 0;
}
