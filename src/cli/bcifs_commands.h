// `lacuna bcifs rules` and `lacuna bcifs measure`: the rule set of a lacunar face, and the topological and
// geometric measures of the faces a recipe describes (with their density maps and plots as PNG).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace lacuna {

// Adds `bcifs rules` and `bcifs measure`. Returns the function that runs whichever was chosen (exit code),
// or -1 from it when none was.
std::function<int()> add_bcifs_commands(CLI::App& app);

}  // namespace lacuna
