// `lacuna curve points` and `lacuna curve fill-rate`: space-filling curves from the command line.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace lacuna {

// Adds `curve points` and `curve fill-rate`. Returns the function that runs whichever was chosen
// (exit code), or -1 from it when none was.
std::function<int()> add_curve_commands(CLI::App& app);

}  // namespace lacuna
