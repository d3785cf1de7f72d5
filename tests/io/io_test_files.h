// Scratch files for the io tests, under the build's test-output directory.
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "core/util/error.h"

namespace rtfact::test {

inline std::string ioTestFile(const std::string& name, const std::string& bytes) {
    const std::filesystem::path dir = std::filesystem::path(RTFACT_TEST_OUT) / "io";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / name).string();
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
}

// Runs f, expecting an rtfact::Error whose message contains `needle`.
inline void expectIoError(const std::function<void()>& f, const std::string& needle) {
    try {
        f();
        ADD_FAILURE() << "no error, expected one containing '" << needle << "'";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << "message: " << e.what();
    }
}

}  // namespace rtfact::test
