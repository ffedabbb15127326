#include "util/system.h"

#include <fcntl.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "errors.h"

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

void release_free_memory() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

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

std::string read_text_file(const std::string& path, const std::string& what, uint64_t max_bytes) {
  // Non-blocking, so that opening a FIFO does not wait for a writer; fstat then says what it is.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw IoError(path + ": cannot open " + what + ": " + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat info;
  if (::fstat(fd, &info) != 0) throw IoError(path + ": cannot read " + what + ": " + std::strerror(errno));
  if (S_ISDIR(info.st_mode)) throw IoError(path + ": is a folder, expected " + what);
  if (!S_ISREG(info.st_mode))
    throw IoError(path + ": is not a regular file (a pipe, socket or device), expected " + what);
  if (uint64_t(info.st_size) > max_bytes)
    throw InvalidInput(path + ": " + what + " is larger than " + format_bytes(max_bytes) + " (" +
                       format_bytes(uint64_t(info.st_size)) + ")");
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  std::string text(size_t(info.st_size), '\0');
  size_t done = 0;
  // A file that grows while it is read is read up to the limit and refused beyond it.
  for (;;) {
    if (done == text.size()) {
      if (text.size() >= max_bytes)
        throw InvalidInput(path + ": " + what + " is larger than " + format_bytes(max_bytes));
      text.resize(std::min<uint64_t>(max_bytes, std::max<uint64_t>(4096, 2 * text.size())));
    }
    const ssize_t n = ::read(fd, &text[done], text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw IoError(path + ": cannot read " + what + ": " + std::strerror(errno));
    if (n == 0) break;
    done += size_t(n);
  }
  text.resize(done);
  return text;
}

}  // namespace lacuna
