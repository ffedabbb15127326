#include "util/progress.h"

#include <cstdio>

namespace lacuna {
namespace {
std::atomic<bool> g_progress_enabled{false};
constexpr int64_t kRedrawIntervalNs = 100'000'000;
}  // namespace

void set_progress_enabled(bool enabled) { g_progress_enabled = enabled; }
bool progress_enabled() { return g_progress_enabled; }

Progress::Progress(std::string stage, uint64_t total)
    : stage_(std::move(stage)),
      total_(total == 0 ? 1 : total),
      start_(std::chrono::steady_clock::now()),
      enabled_(g_progress_enabled) {
  if (enabled_) draw(0);
}

Progress::~Progress() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(draw_mutex_);
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
}

void Progress::advance(uint64_t n) {
  uint64_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
  if (!enabled_) return;
  int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                    std::chrono::steady_clock::now() - start_).count();
  int64_t next = next_draw_ns_.load(std::memory_order_relaxed);
  if (now < next) return;
  if (!next_draw_ns_.compare_exchange_strong(next, now + kRedrawIntervalNs)) return;
  std::unique_lock<std::mutex> lock(draw_mutex_, std::try_to_lock);
  if (lock.owns_lock()) draw(done);
}

void Progress::draw(uint64_t done) {
  constexpr int kWidth = 30;
  double fraction = done >= total_ ? 1.0 : static_cast<double>(done) / static_cast<double>(total_);
  int filled = static_cast<int>(fraction * kWidth);
  char bar[kWidth + 1];
  for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '.';
  bar[kWidth] = '\0';
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "\r\033[K%-12s [%s] %3d%%  %.1f s", stage_.c_str(), bar,
               static_cast<int>(fraction * 100.0), seconds);
  std::fflush(stderr);
}

}  // namespace lacuna
