// What the process can learn about the machine and itself: memory and time.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace lacuna {

// Physical memory available to this process in bytes: the machine's RAM, or the cgroup limit
// when one is set and smaller.
uint64_t available_memory_bytes();

// Peak resident set size of this process so far, in bytes (VmHWM); 0 where unknown.
uint64_t peak_memory_bytes();

// Peak resident set size of the largest child process this process has waited for (TetGen runs
// in one), in bytes; 0 where unknown.
uint64_t peak_child_memory_bytes();

// Resident set size of this process now, in bytes (VmRSS); 0 where unknown.
uint64_t current_memory_bytes();

// Hands the heap memory freed so far back to the system: glibc keeps freed pages of its heaps
// mapped, and the resident memory (and so the peak a run reports and is held to) counts them. A
// no-op where the C library has no malloc_trim.
void release_free_memory();

// Wall-clock seconds per named stage, in the order the stages ran.
class StageTimer {
 public:
  // Starts timing `stage`; the previous stage, if any, ends now.
  void start(const std::string& stage);
  // Ends the current stage.
  void stop();
  const std::vector<std::pair<std::string, double>>& seconds() const { return seconds_; }

 private:
  std::vector<std::pair<std::string, double>> seconds_;
  std::chrono::steady_clock::time_point started_;
  bool running_ = false;
};

// Formats a byte count for messages, e.g. "3.2 GB".
std::string format_bytes(uint64_t bytes);

// The whole content of the regular file at `path` (`what` names it in messages, e.g. "the recipe
// file"). Refuses folders, pipes and devices without opening them for reading (a FIFO would block, a
// device never ends), and files over `max_bytes` before reading them. Throws IoError when the file is
// missing, unreadable or not a regular file, InvalidInput when it is larger than `max_bytes`.
std::string read_text_file(const std::string& path, const std::string& what, uint64_t max_bytes);

}  // namespace lacuna
