// Checks of numeric command-line options with short messages: CLI11's PositiveNumber accepts "nan"
// and prints its upper bound, the largest double, with all 309 digits.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <string>

#include "errors.h"

namespace lacuna {

// A finite number from `low` to `high` (each bound inclusive unless `open_low`): "nan", "inf" and
// text after the number are refused.
inline CLI::Validator number_in(double low, double high, bool open_low = false) {
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        const char* begin = text.c_str();
        char* end = nullptr;
        const double v = std::strtod(begin, &end);
        if (end == begin || *end != '\0' || !std::isfinite(v)) return "expected a finite number, got \"" + text + "\"";
        if (open_low ? !(v > low) : !(v >= low)) {
          return std::string("expected a number ") + (open_low ? "above " : "of at least ") + message_number(low) +
                 ", got " + text;
        }
        if (v > high) return "expected a number of at most " + message_number(high) + ", got " + text;
        return "";
      },
      open_low ? "NUMBER > " + message_number(low) : "NUMBER >= " + message_number(low));
}

// A finite number above 0.
inline CLI::Validator positive_number() { return number_in(0, HUGE_VAL, true); }
// A finite number of at least 0.
inline CLI::Validator non_negative_number() { return number_in(0, HUGE_VAL); }
// Any finite number.
inline CLI::Validator finite_number() { return number_in(-HUGE_VAL, HUGE_VAL); }

}  // namespace lacuna
