#include "cli/terminal_progress.h"

#include <cstdio>

namespace lacuna {
namespace {
constexpr int64_t kRedrawIntervalNs = 100'000'000;
}  // namespace

void TerminalProgress::begin(const std::string& stage, uint64_t total) {
  auto bar = std::make_unique<Bar>();
  bar->stage = stage;
  bar->total = total == 0 ? 1 : total;
  bar->start = std::chrono::steady_clock::now();
  Bar* raw = bar.get();
  {
    std::lock_guard<std::mutex> lock(stack_mutex_);
    stack_.push_back(std::move(bar));
    top_ = raw;
  }
  std::lock_guard<std::mutex> lock(draw_mutex_);
  draw(*raw, 0);
}

void TerminalProgress::advance(uint64_t n) {
  Bar* bar = top_.load();
  if (!bar) return;
  uint64_t done = bar->done.fetch_add(n, std::memory_order_relaxed) + n;
  int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - bar->start).count();
  int64_t next = bar->next_draw_ns.load(std::memory_order_relaxed);
  if (now < next) return;
  if (!bar->next_draw_ns.compare_exchange_strong(next, now + kRedrawIntervalNs)) return;
  std::unique_lock<std::mutex> lock(draw_mutex_, std::try_to_lock);
  if (lock.owns_lock()) draw(*bar, done);
}

void TerminalProgress::end() {
  {
    std::lock_guard<std::mutex> lock(stack_mutex_);
    if (stack_.empty()) return;
    ended_.push_back(std::move(stack_.back()));
    stack_.pop_back();
    top_ = stack_.empty() ? nullptr : stack_.back().get();
  }
  std::lock_guard<std::mutex> lock(draw_mutex_);
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
}

void TerminalProgress::draw(const Bar& bar, uint64_t done) {
  constexpr int kWidth = 30;
  double fraction = done >= bar.total ? 1.0 : static_cast<double>(done) / static_cast<double>(bar.total);
  int filled = static_cast<int>(fraction * kWidth);
  char line[kWidth + 1];
  for (int i = 0; i < kWidth; ++i) line[i] = i < filled ? '#' : '.';
  line[kWidth] = '\0';
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - bar.start).count();
  std::fprintf(stderr, "\r\033[K%-12s [%s] %3d%%  %.1f s", bar.stage.c_str(), line, static_cast<int>(fraction * 100.0),
               seconds);
  std::fflush(stderr);
}

}  // namespace lacuna
