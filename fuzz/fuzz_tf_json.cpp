// libFuzzer harness: transfer-function JSON (ParaView presets and our own format).
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/util/error.h"
#include "volume/transfer_function.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        const auto tf = rtfact::volume::parseTransferFunctionJson(
            std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
        const auto table = rtfact::volume::buildTable(tf, {0.0f, 1.0f}, 0.5f, 256);
        (void)table;
    } catch (const rtfact::Error&) {
    }
    return 0;
}
