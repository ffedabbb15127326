// `lacuna voronoi rules` and `lacuna voronoi cells`: the substitution rules of a fractal Voronoi
// partition and its measured cell measures.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace lacuna {

// Adds `voronoi rules` and `voronoi cells`. Returns the function that runs whichever was chosen (exit
// code), or -1 from it when none was.
std::function<int()> add_voronoi_commands(CLI::App& app);

}  // namespace lacuna
