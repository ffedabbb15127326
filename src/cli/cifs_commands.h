// Inspection of CIFS systems and NURBS automata from the command line (machine-readable).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace lacuna {

// Adds `cifs info`, `cifs tessellate`, `nurbs automaton` and `nurbs tessellate` to the program.
// Returns the function that runs whichever of them was chosen (exit code), or an empty function
// when none was.
std::function<int()> add_cifs_commands(CLI::App& app);

}  // namespace lacuna
