// The command line's progress bars: one line on stderr per running stage, redrawn at most ten
// times a second and erased when the stage ends.
#pragma once

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "util/progress.h"

namespace lacuna {

// Draws the innermost stage's bar on stderr; the caller decides whether stderr is a terminal.
class TerminalProgress : public ProgressSink {
 public:
  void begin(const std::string& stage, uint64_t total) override;
  void advance(uint64_t n) override;
  void end() override;

 private:
  struct Bar {
    std::string stage;
    uint64_t total = 1;
    std::atomic<uint64_t> done{0};
    std::atomic<int64_t> next_draw_ns{0};
    std::chrono::steady_clock::time_point start;
  };
  void draw(const Bar& bar, uint64_t done);

  std::mutex stack_mutex_;
  std::vector<std::unique_ptr<Bar>> stack_;
  // Ended bars stay allocated: a worker may still be advancing one while its stage unwinds.
  std::vector<std::unique_ptr<Bar>> ended_;
  std::atomic<Bar*> top_{nullptr};
  std::mutex draw_mutex_;
};

}  // namespace lacuna
