// What several test files share: a temporary folder per test, whole-file reading and writing, and
// running a command (or the `lacuna` program) with its exit code and output.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace lacuna {
namespace test {

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A fresh folder named after the running test (and the process), removed with everything in it.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "lacuna-" + std::string(info ? info->test_suite_name() : "none") + "-" +
                       (info ? info->name() : "none") + "-" + std::to_string(::getpid()) + "-" +
                       std::to_string(counter_++);
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

// A shell word: the text in single quotes (paths here hold no quote).
inline std::string quote(const std::string& s) { return "'" + s + "'"; }

struct Result {
  int code = -1;  // the exit status; -1 when ended by a signal
  std::string out, err;
  double seconds = 0;
};

// Runs a shell command line; its output goes through files in `scratch`, removed afterwards.
inline Result run(const std::string& command, const std::filesystem::path& scratch) {
  Result r;
  const std::filesystem::path out = scratch / ".stdout", err = scratch / ".stderr";
  const std::string line = command + " > " + quote(out.string()) + " 2> " + quote(err.string());
  const auto start = std::chrono::steady_clock::now();
  const int status = std::system(line.c_str());
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

#ifdef LACUNA_BINARY
// The `lacuna` program with these arguments (a shell-quoted string).
inline Result lacuna(const std::string& args, const std::filesystem::path& scratch) {
  return run(quote(LACUNA_BINARY) + " " + args, scratch);
}
#endif

// Whether a program is on the PATH.
inline bool have(const char* program) {
  return std::system((std::string("command -v ") + program + " > /dev/null 2>&1").c_str()) == 0;
}

}  // namespace test
}  // namespace lacuna
