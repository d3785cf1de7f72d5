// Key/value statistics of a run (load, prepare, build, render): the engine fills them,
// `rtfact --stats` prints them as key=value lines, in the order they were added.
#pragma once
#include <chrono>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace rtfact::engine {

class Stats {
   public:
    void add(const std::string& key, const std::string& value) { kv_.emplace_back(key, value); }
    void add(const std::string& key, const char* value) { add(key, std::string(value)); }
    void add(const std::string& key, double value) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.3f", value);
        add(key, std::string(buf));
    }
    void add(const std::string& key, long long value) { add(key, std::to_string(value)); }
    void add(const std::string& key, int value) { add(key, std::to_string(value)); }
    void add(const std::string& key, unsigned long long value) { add(key, std::to_string(value)); }
    void add(const std::string& key, unsigned long value) { add(key, std::to_string(value)); }
    void append(const Stats& other) { kv_.insert(kv_.end(), other.kv_.begin(), other.kv_.end()); }
    // The value of `key` ("" when absent).
    std::string get(const std::string& key) const {
        for (const auto& [k, v] : kv_)
            if (k == key) return v;
        return {};
    }
    const std::vector<std::pair<std::string, std::string>>& entries() const { return kv_; }
    void print() const {
        for (const auto& [k, v] : kv_) std::printf("%s=%s\n", k.c_str(), v.c_str());
        std::fflush(stdout);
    }

   private:
    std::vector<std::pair<std::string, std::string>> kv_;
};

// Milliseconds since `t0`.
inline double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace rtfact::engine
