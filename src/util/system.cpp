#include "util/system.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace lacuna {

uint64_t available_memory_bytes() {
  uint64_t physical = static_cast<uint64_t>(sysconf(_SC_PHYS_PAGES)) *
                      static_cast<uint64_t>(sysconf(_SC_PAGE_SIZE));
  for (const char* path : {"/sys/fs/cgroup/memory.max",
                           "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(path);
    std::string text;
    if (in >> text && !text.empty() && text != "max") {
      uint64_t limit = 0;
      std::istringstream(text) >> limit;
      if (limit > 0 && limit < physical) physical = limit;
    }
  }
  return physical;
}

namespace {
uint64_t status_field_bytes(const char* field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  const std::string prefix = std::string(field) + ":";
  while (std::getline(in, line)) {
    if (line.rfind(prefix, 0) == 0) {
      uint64_t kib = 0;
      std::istringstream(line.substr(prefix.size())) >> kib;
      return kib * 1024;
    }
  }
  return 0;
}
}  // namespace

uint64_t peak_memory_bytes() { return status_field_bytes("VmHWM"); }

uint64_t current_memory_bytes() { return status_field_bytes("VmRSS"); }

uint64_t peak_child_memory_bytes() {
  rusage usage{};
  if (getrusage(RUSAGE_CHILDREN, &usage) != 0) return 0;
  return uint64_t(usage.ru_maxrss) * 1024;  // kilobytes on Linux
}

void StageTimer::start(const std::string& stage) {
  stop();
  seconds_.emplace_back(stage, 0.0);
  started_ = std::chrono::steady_clock::now();
  running_ = true;
}

void StageTimer::stop() {
  if (!running_) return;
  seconds_.back().second +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  running_ = false;
}

std::string format_bytes(uint64_t bytes) {
  char text[32];
  double b = static_cast<double>(bytes);
  if (b >= 1e9) std::snprintf(text, sizeof text, "%.1f GB", b / 1e9);
  else if (b >= 1e6) std::snprintf(text, sizeof text, "%.1f MB", b / 1e6);
  else if (b >= 1e3) std::snprintf(text, sizeof text, "%.1f kB", b / 1e3);
  else std::snprintf(text, sizeof text, "%llu B", static_cast<unsigned long long>(bytes));
  return text;
}

}  // namespace lacuna
