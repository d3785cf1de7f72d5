// Progress bar on stderr for long work (loading, building, rendering); silent when
// stderr is not a terminal or when disabled (--quiet). Thread safe.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace rtfact {

class Progress {
   public:
    Progress(std::string label, uint64_t total, bool enabled);
    ~Progress();
    void add(uint64_t n = 1);
    void finish();
    static bool terminalAvailable();

   private:
    void draw(uint64_t done, bool force);
    std::string label_;
    uint64_t total_;
    bool enabled_;
    bool finished_ = false;
    std::atomic<uint64_t> done_{0};
    std::atomic<int64_t> lastDrawMs_{-1000};
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_;
};

// Global switch set by the CLI's --quiet.
void setProgressEnabled(bool enabled);
bool progressEnabled();

}  // namespace rtfact
