// Utilities: the memory budget check and error formatting.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

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

// Restores an environment variable when the test leaves, even through an exception, so
// that later tests in the same process do not inherit the cap.
class ScopedEnv {
   public:
    explicit ScopedEnv(const char* name) : name_(name) {
        if (const char* v = std::getenv(name)) old_ = v;
    }
    ~ScopedEnv() {
        if (old_)
            ::setenv(name_, old_->c_str(), 1);
        else
            ::unsetenv(name_);
    }
    void set(const char* value) const { ::setenv(name_, value, 1); }

   private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(MemoryBudget, UserLimitFromTheEnvironment) {
    const ScopedEnv env("RTFACT_MEMORY_LIMIT");
    env.set("64M");
    EXPECT_EQ(availableMemoryBytes(), uint64_t(64) << 20);
    EXPECT_NO_THROW(checkMemory("a.ply", 32u << 20, "a cloud"));
    EXPECT_THROW(checkMemory("a.ply", 60u << 20, "a cloud"), Error);  // above 90 % of the cap
    env.set("1.5GiB");
    EXPECT_EQ(availableMemoryBytes(), uint64_t(1.5 * 1024 * 1024 * 1024));
    for (const char* bad : {"lots", "12Q", "-1G", "0"}) {
        env.set(bad);
        try {
            availableMemoryBytes();
            ADD_FAILURE() << "accepted RTFACT_MEMORY_LIMIT=" << bad;
        } catch (const Error& e) {
            EXPECT_EQ(e.file(), "RTFACT_MEMORY_LIMIT");
        }
    }
}

TEST(ErrorFormat, FileAndMessage) {
    EXPECT_EQ(Error("a.ply", "truncated").message(), "a.ply: truncated");
    EXPECT_EQ(Error("", "bad").message(), "bad");
}
