// The three kinds of errors Lacuna reports to users, and the exit codes they map to.
// Validity of a mesh is data (a report), never an exception.
#pragma once

#include <stdexcept>
#include <string>

namespace lacuna {

// Exit codes of the `lacuna` program.
enum ExitCode : int {
  kExitOk = 0,
  kExitInternal = 1,       // a bug: an unexpected exception
  kExitBadInput = 2,       // bad usage, recipe or mesh file
  kExitResourceLimit = 3,  // memory or size budget exceeded
  kExitCheckFailed = 4,    // the result failed a validity check
};

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  virtual int exit_code() const = 0;
};

// Bad arguments, malformed recipes, broken input meshes: what was wrong and where.
class InvalidInput : public Error {
 public:
  using Error::Error;
  int exit_code() const override { return kExitBadInput; }
};

// A file that cannot be opened, read or written.
class IoError : public Error {
 public:
  using Error::Error;
  int exit_code() const override { return kExitBadInput; }
};

// A memory or size budget that the job would exceed; the message says what would fit.
class ResourceLimit : public Error {
 public:
  using Error::Error;
  int exit_code() const override { return kExitResourceLimit; }
};

}  // namespace lacuna
