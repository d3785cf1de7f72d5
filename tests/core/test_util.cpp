// Utilities: the memory budget check and error formatting.
#include <gtest/gtest.h>

#include <cstdlib>

#include "core/util/error.h"
#include "core/util/memory_budget.h"

using namespace rtfact;

TEST(MemoryBudget, RejectsAbsurdRequestsWithAHint) {
    EXPECT_GT(availableMemoryBytes(), uint64_t(1) << 20);
    EXPECT_NO_THROW(checkMemory("small.raw", 1 << 20, "a small grid"));
    try {
        checkMemory("huge.raw", uint64_t(1) << 60, "the dense grid", "try --lod");
        FAIL() << "no error for an exabyte";
    } catch (const Error& e) {
        EXPECT_EQ(e.file(), "huge.raw");
        const std::string m = e.message();
        EXPECT_NE(m.find("needs 1073741824.0 GiB for the dense grid"), std::string::npos) << m;
        EXPECT_NE(m.find("(try --lod)"), std::string::npos) << m;
    }
    EXPECT_EQ(formatBytes(3u << 20), "3.0 MiB");
}

TEST(MemoryBudget, UserLimitFromTheEnvironment) {
    ::setenv("RTFACT_MEMORY_LIMIT", "64M", 1);
    EXPECT_EQ(availableMemoryBytes(), uint64_t(64) << 20);
    EXPECT_NO_THROW(checkMemory("a.ply", 32u << 20, "a cloud"));
    EXPECT_THROW(checkMemory("a.ply", 60u << 20, "a cloud"), Error);  // above 90 % of the cap
    ::setenv("RTFACT_MEMORY_LIMIT", "1.5GiB", 1);
    EXPECT_EQ(availableMemoryBytes(), uint64_t(1.5 * 1024 * 1024 * 1024));
    for (const char* bad : {"lots", "12Q", "-1G", "0"}) {
        ::setenv("RTFACT_MEMORY_LIMIT", bad, 1);
        try {
            availableMemoryBytes();
            ADD_FAILURE() << "accepted RTFACT_MEMORY_LIMIT=" << bad;
        } catch (const Error& e) {
            EXPECT_EQ(e.file(), "RTFACT_MEMORY_LIMIT");
        }
    }
    ::unsetenv("RTFACT_MEMORY_LIMIT");
}

TEST(ErrorFormat, FileAndMessage) {
    EXPECT_EQ(Error("a.ply", "truncated").message(), "a.ply: truncated");
    EXPECT_EQ(Error("", "bad").message(), "bad");
}
