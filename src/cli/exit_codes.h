// Exit codes of the `lacuna` program, and the one place that maps the library's errors to them.
#pragma once

#include <exception>

namespace lacuna {

enum ExitCode : int {
  kExitOk = 0,
  kExitInternal = 1,       // a bug: an unexpected exception
  kExitBadInput = 2,       // bad usage, recipe or mesh file
  kExitResourceLimit = 3,  // memory or size budget exceeded
  kExitCheckFailed = 4,    // the result failed a validity check
};

// The exit code for an error that ended a command: bad input and files 2, budgets and running out
// of memory 3, failed checks 4, anything else (a bug, a cancellation) 1.
int exit_code(const std::exception& error);

}  // namespace lacuna
