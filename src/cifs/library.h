// The shipped systems, and CIFS descriptions in JSON (files a user writes, recipe inputs).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cifs/automaton.h"

namespace lacuna {
namespace cifs {

// Names of the shipped fixed systems: sierpinski_triangle, sierpinski_tetrahedron,
// menger_sponge, cantor_dust_2d, cantor_dust_3d, koch_curve, takagi_curve, bspline_quadratic,
// bspline_cubic.
std::vector<std::string> library_names();

// A shipped system with its default control points (unit size, at the origin). Throws
// InvalidInput for an unknown name, suggesting the closest.
Cifs library_system(const std::string& name);

// A system described in JSON: a library name, or an object with exactly one of
//   "library": NAME
//   "states" + "transitions" (+ "initial", "alphabet_size"): an explicit automaton
//   "nurbs_curve": {"degree", "knots"}
//   "nurbs_surface": {"u": {"degree", "knots"}, "v": {"degree", "knots"}}
//   "product": [SYSTEM, SYSTEM]            (tensor product; default control points a(u) + b(v))
//   "restrict": SYSTEM with "drop_symbols": [..] or "pattern": {"states", "transitions"}
// and optionally "control_points_mm" (replaces the default; [x, y, z] or [x, y, z, w] each, a list of
// rows for products), "scale" and "translate_mm" (applied to the control points). `path` names the
// object in messages. Throws InvalidInput naming the file and JSON path.
Cifs parse_system(const nlohmann::json& value, const std::string& file, const std::string& path);

// Reads a system from a JSON file, or takes a library name when `name_or_file` is one.
Cifs load_system(const std::string& name_or_file);

// The automaton and control points as JSON (states with control point counts, primitives,
// stationary flags and primitive vertices; transitions with matrices; control points).
nlohmann::json system_json(const Cifs& cifs);

}  // namespace cifs
}  // namespace lacuna
