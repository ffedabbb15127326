// `lacuna fill pattern`: a random fractal filling of a wallpaper group's fundamental region, as JSON
// and an SVG picture.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace lacuna {

// Adds `fill pattern`. Returns the function that runs it (exit code), or -1 from it when it was
// not chosen.
std::function<int()> add_fill_commands(CLI::App& app);

}  // namespace lacuna
