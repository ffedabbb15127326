#include "export/output_files.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>

#include "errors.h"

namespace lacuna {
namespace {

// "<dir>/.<name>.tmp-<pid>-<counter>": hidden, in the same directory (so that the rename is
// atomic), and unique across the threads and processes that write there.
std::string temporary_path(const std::string& final_path) {
  static std::atomic<uint64_t> counter{0};
  std::filesystem::path path(final_path);
  std::string name = "." + path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                     std::to_string(counter++);
  return (path.parent_path() / name).string();
}

}  // namespace

OutputTransaction::~OutputTransaction() {
  if (!done_) rollback();
}

std::string OutputTransaction::stage(const std::string& final_path) {
  if (done_) throw std::logic_error("OutputTransaction::stage after commit or rollback");
  if (final_path.empty() || std::filesystem::path(final_path).filename().empty()) {
    throw InvalidInput("'" + final_path + "' is not a file name");
  }
  for (const Entry& entry : entries_) {
    if (entry.final_path == final_path) throw InvalidInput("'" + final_path + "' is written twice");
  }
  entries_.push_back({temporary_path(final_path), final_path});
  return entries_.back().temp_path;
}

void OutputTransaction::commit() {
  if (done_) throw std::logic_error("OutputTransaction::commit after commit or rollback");
  done_ = true;
  for (size_t i = 0; i < entries_.size(); ++i) {
    if (std::rename(entries_[i].temp_path.c_str(), entries_[i].final_path.c_str()) != 0) {
      int error = errno;
      for (size_t j = i; j < entries_.size(); ++j) std::remove(entries_[j].temp_path.c_str());
      throw IoError("cannot move '" + entries_[i].temp_path + "' to '" + entries_[i].final_path +
                    "': " + std::strerror(error));
    }
  }
}

void OutputTransaction::rollback() {
  done_ = true;
  for (const Entry& entry : entries_) std::remove(entry.temp_path.c_str());
}

void write_text_file_atomically(const std::string& path, const std::string& text) {
  OutputTransaction transaction;
  std::string temp = transaction.stage(path);
  std::FILE* file = std::fopen(temp.c_str(), "wb");
  if (!file) {
    throw IoError("cannot create '" + temp + "' for '" + path + "': " + std::strerror(errno));
  }
  bool written = std::fwrite(text.data(), 1, text.size(), file) == text.size();
  int error = errno;
  if (std::fclose(file) != 0 && written) {
    written = false;
    error = errno;
  }
  if (!written) throw IoError("cannot write '" + path + "': " + std::strerror(error));
  transaction.commit();
}

}  // namespace lacuna
