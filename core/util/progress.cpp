#include "core/util/progress.h"

#include <unistd.h>

#include <cstdio>

namespace rtfact {

namespace {
std::atomic<bool> gEnabled{true};
}

void setProgressEnabled(bool enabled) { gEnabled = enabled; }
bool progressEnabled() { return gEnabled; }

bool Progress::terminalAvailable() { return isatty(STDERR_FILENO) != 0; }

Progress::Progress(std::string label, uint64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total ? total : 1),
      enabled_(enabled && gEnabled && terminalAvailable()),
      start_(std::chrono::steady_clock::now()) {
    if (enabled_) draw(0, true);
}

Progress::~Progress() { finish(); }

void Progress::add(uint64_t n) {
    const uint64_t d = done_.fetch_add(n) + n;
    if (enabled_) draw(d, false);
}

void Progress::finish() {
    if (!enabled_ || finished_) return;
    finished_ = true;
    draw(total_, true);
    std::lock_guard<std::mutex> lock(mutex_);
    std::fputc('\n', stderr);
    std::fflush(stderr);
}

void Progress::draw(uint64_t done, bool force) {
    const auto now = std::chrono::steady_clock::now();
    const int64_t ms = std::chrono::duration_cast<std::chrono::milliseconds>(now - start_).count();
    int64_t last = lastDrawMs_.load();
    if (!force && (ms - last < 100 || !lastDrawMs_.compare_exchange_strong(last, ms))) return;
    std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() && !force) return;
    if (!lock.owns_lock()) lock.lock();
    const double f = done >= total_ ? 1.0 : double(done) / double(total_);
    const int width = 30, fill = int(f * width);
    std::string bar(size_t(fill), '#');
    bar.resize(size_t(width), ' ');
    std::fprintf(stderr, "\r%-10s [%s] %3d%% %6.1fs", label_.c_str(), bar.c_str(), int(f * 100.0), double(ms) / 1000.0);
    std::fflush(stderr);
}

}  // namespace rtfact
