#include "export/output_files.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <unordered_set>

#include "errors.h"

namespace lacuna {
namespace {

// What this process has on disk that a finished job would not leave: temporaries, lock files and
// folders it created. Never destroyed, so that it outlives every object that uses it.
struct Unfinished {
  std::mutex mutex;
  std::vector<std::pair<std::string, bool>> paths;  // (path, is a folder), in the order they appeared
};

Unfinished& unfinished() {
  static Unfinished* registry = new Unfinished;
  return *registry;
}

void track(const std::string& path, bool folder) {
  Unfinished& u = unfinished();
  std::lock_guard<std::mutex> lock(u.mutex);
  u.paths.emplace_back(path, folder);
}

void untrack(const std::string& path) {
  Unfinished& u = unfinished();
  std::lock_guard<std::mutex> lock(u.mutex);
  for (size_t i = u.paths.size(); i-- > 0;)
    if (u.paths[i].first == path) {
      u.paths.erase(u.paths.begin() + long(i));
      return;
    }
}

// Untracks many paths in one pass (a job may stage thousands of layers).
void untrack_all(const std::unordered_set<std::string>& paths) {
  Unfinished& u = unfinished();
  std::lock_guard<std::mutex> lock(u.mutex);
  u.paths.erase(std::remove_if(u.paths.begin(), u.paths.end(),
                               [&](const std::pair<std::string, bool>& p) { return paths.count(p.first) > 0; }),
                u.paths.end());
}

// "<dir>/.<name>.tmp-<pid>-<counter>": hidden, in the same directory (so that the rename is
// atomic), and unique across the threads and processes that write there.
std::string temporary_path(const std::string& final_path) {
  static std::atomic<uint64_t> counter{0};
  std::filesystem::path path(final_path);
  std::string name = "." + path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                     std::to_string(counter++);
  return (path.parent_path() / name).string();
}

bool all_digits(const std::string& text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Whether the process `pid` is gone (not merely someone else's).
bool process_gone(long pid) { return pid > 0 && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH; }

}  // namespace

bool is_output_temporary(const std::string& name, long* pid) {
  if (name.size() < 2 || name[0] != '.') return false;
  const size_t tmp = name.rfind(".tmp-");
  if (tmp == std::string::npos || tmp == 0) return false;
  const std::string tail = name.substr(tmp + 5);
  const size_t dash = tail.find('-');
  if (dash == std::string::npos || !all_digits(tail.substr(0, dash)) || !all_digits(tail.substr(dash + 1)) ||
      dash > 9)
    return false;
  if (pid) *pid = std::strtol(tail.substr(0, dash).c_str(), nullptr, 10);
  return true;
}

OutputTransaction::~OutputTransaction() {
  if (!done_) rollback();
}

ScratchFile::ScratchFile(std::string path) : path_(std::move(path)) { track(path_, false); }

ScratchFile::~ScratchFile() {
  std::error_code ignored;
  std::filesystem::remove(path_, ignored);
  untrack(path_);
}

std::string OutputTransaction::stage(const std::string& final_path) {
  if (done_) throw std::logic_error("OutputTransaction::stage after commit or rollback");
  if (final_path.empty() || std::filesystem::path(final_path).filename().empty()) {
    throw InvalidInput("'" + final_path + "' is not a file name");
  }
  if (!finals_.insert(final_path).second) throw InvalidInput("'" + final_path + "' is written twice");
  entries_.push_back({temporary_path(final_path), final_path});
  temporaries_.insert(entries_.back().temp_path);
  track(entries_.back().temp_path, false);
  return entries_.back().temp_path;
}

void OutputTransaction::commit() {
  if (done_) throw std::logic_error("OutputTransaction::commit after commit or rollback");
  done_ = true;
  // A temporary renamed is gone: removing it again (an interrupt before the untracking below) does nothing.
  for (size_t i = 0; i < entries_.size(); ++i) {
    if (std::rename(entries_[i].temp_path.c_str(), entries_[i].final_path.c_str()) != 0) {
      int error = errno;
      for (size_t j = i; j < entries_.size(); ++j) std::remove(entries_[j].temp_path.c_str());
      untrack_all(temporaries_);
      throw IoError("cannot move the new '" + entries_[i].final_path + "' into place: " + std::strerror(error));
    }
  }
  untrack_all(temporaries_);
}

void OutputTransaction::rollback() {
  done_ = true;
  for (const Entry& entry : entries_) std::remove(entry.temp_path.c_str());
  untrack_all(temporaries_);
}

void write_whole_file(const std::string& path, const std::string& bytes) {
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) {
    throw IoError("cannot create '" + path + "': " + std::strerror(errno));
  }
  bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  int error = errno;
  if (std::fclose(file) != 0 && written) {
    written = false;
    error = errno;
  }
  if (!written) throw IoError("cannot write '" + path + "': " + std::strerror(error));
}

void write_text_file_atomically(const std::string& path, const std::string& text) {
  OutputTransaction transaction;
  try {
    write_whole_file(transaction.stage(path), text);
  } catch (const IoError& e) {
    throw IoError(transaction.with_final_names(e.what()));  // named as asked, not as its temporary
  }
  transaction.commit();
}

OutputFolder::OutputFolder(const std::string& path) : path_(path.empty() ? "." : path) {
  namespace fs = std::filesystem;
  lock_path_ = (fs::path(path_) / kOutputLockName).string();
  // Creates the missing folders of the path, outermost first, remembering those made here.
  auto create = [&] {
    fs::path prefix;
    for (const fs::path& part : fs::path(path_)) {
      prefix /= part;
      if (::mkdir(prefix.c_str(), 0777) == 0) {
        created_.push_back(prefix.string());
        track(prefix.string(), true);
        continue;
      }
      const int error = errno;
      struct stat info;
      if (::stat(prefix.c_str(), &info) == 0) {
        if (!S_ISDIR(info.st_mode)) throw IoError(prefix.string() + ": exists and is not a folder");
        continue;
      }
      throw IoError(path_ + ": cannot create the output folder: " + std::strerror(error));
    }
  };
  for (int attempt = 0;; ++attempt) {
    create();
    const int fd = ::open(lock_path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) {
      // A failed job removed the folder it had made between our mkdir and open: make it again.
      if (errno == ENOENT && attempt < 20) continue;
      throw IoError(path_ + ": cannot lock the output folder: " + std::strerror(errno));
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      char text[32] = {0};
      const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
      ::close(fd);
      if (error != EWOULDBLOCK) throw IoError(path_ + ": cannot lock the output folder: " + std::strerror(error));
      const std::string holder = n > 0 ? std::string(text, size_t(n)) : std::string();
      // This job made nothing here yet that it should leave; folders it created are removed below.
      for (size_t i = created_.size(); i-- > 0;) {
        ::rmdir(created_[i].c_str());
        untrack(created_[i]);
      }
      created_.clear();
      throw ResourceLimit(path_ + ": the output folder is busy: another Lacuna run" +
                          (all_digits(holder) ? " (process " + holder + ")" : std::string()) +
                          " is writing to it; wait for it to finish or choose another output folder");
    }
    // The holder before us may have removed the lock file after we opened it: lock the file that is
    // there now.
    struct stat held, now;
    if (::fstat(fd, &held) != 0 || ::stat(lock_path_.c_str(), &now) != 0 || held.st_ino != now.st_ino ||
        held.st_dev != now.st_dev) {
      ::close(fd);
      if (attempt < 20) continue;
      throw IoError(path_ + ": cannot lock the output folder: its lock file keeps changing");
    }
    lock_fd_ = fd;
    break;
  }
  track(lock_path_, false);
  const std::string pid = std::to_string(::getpid());
  if (::ftruncate(lock_fd_, 0) != 0 || ::pwrite(lock_fd_, pid.data(), pid.size(), 0) != ssize_t(pid.size())) {
    // The lock holds without the process number; only the busy message of another job misses it.
  }
  // Temporaries of killed runs: nobody else writes here while we hold the lock, and their writers are gone.
  if (DIR* dir = ::opendir(path_.c_str())) {
    while (const dirent* entry = ::readdir(dir)) {
      long writer = 0;
      if (is_output_temporary(entry->d_name, &writer) && writer != long(::getpid()) && process_gone(writer) &&
          ::unlink((fs::path(path_) / entry->d_name).c_str()) == 0)
        ++stale_removed_;
    }
    ::closedir(dir);
  }
}

OutputFolder::~OutputFolder() {
  // Removed while still held, so that a job waiting on the old file notices and takes a new one.
  ::unlink(lock_path_.c_str());
  untrack(lock_path_);
  ::close(lock_fd_);
  for (size_t i = created_.size(); i-- > 0;) {
    if (!keep_) ::rmdir(created_[i].c_str());
    untrack(created_[i]);
  }
}

void remove_unfinished_outputs() {
  Unfinished& u = unfinished();
  // Held until the process ends: a thread that stages another file now waits instead.
  u.mutex.lock();
  for (const auto& [path, folder] : u.paths)
    if (!folder) ::unlink(path.c_str());
  for (size_t i = u.paths.size(); i-- > 0;)
    if (u.paths[i].second) ::rmdir(u.paths[i].first.c_str());
  u.paths.clear();
}

}  // namespace lacuna
