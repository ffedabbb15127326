// A progress bar for long stages, drawn on stderr only when it is a terminal and not silenced.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace lacuna {

// Turns progress output on or off for the whole program (off by default; the command line turns
// it on when stderr is a terminal and --quiet is not given).
void set_progress_enabled(bool enabled);
bool progress_enabled();

// One stage's bar. advance() may be called from any thread; the bar is redrawn at most ten times
// a second and erased when the stage ends.
class Progress {
 public:
  Progress(std::string stage, uint64_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(uint64_t n = 1);

 private:
  void draw(uint64_t done);

  std::string stage_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::atomic<int64_t> next_draw_ns_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex draw_mutex_;
  bool enabled_;
};

}  // namespace lacuna
