// The kinds of errors Lacuna's library reports. Front ends decide what each means to them (the
// command line maps them to exit codes in cli/exit_codes.h). Validity of a mesh is data (a
// report), never an exception.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <string>

namespace lacuna {

// A number for messages: six significant digits ("1.79769e+308", not std::to_string's 309 digits).
inline std::string message_number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

// Every error the library throws on purpose; what() is a message a user can act on.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Bad arguments, malformed recipes, broken input meshes: what was wrong and where.
class InvalidInput : public Error {
 public:
  using Error::Error;
};

// A file that cannot be opened, read or written.
class IoError : public Error {
 public:
  using Error::Error;
};

// A memory or size budget that the job would exceed; the message says what would fit.
class ResourceLimit : public Error {
 public:
  using Error::Error;
};

// A result that failed a validity check, for callers that want an error rather than a report.
class CheckFailed : public Error {
 public:
  using Error::Error;
};

// A broken invariant inside Lacuna: a bug, not something the user can fix.
class InternalError : public Error {
 public:
  using Error::Error;
};

// The caller's progress sink asked to stop; nothing was left behind.
class Cancelled : public Error {
 public:
  using Error::Error;
};

}  // namespace lacuna
