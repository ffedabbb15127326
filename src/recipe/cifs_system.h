// CIFS systems described in JSON (files a user writes, recipe inputs) read into cifs::Cifs, and written
// back out as JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "cifs/automaton.h"

namespace lacuna {
namespace cifs {

// A system described in JSON: a library name, or an object with exactly one of
//   "library": NAME
//   "states" + "transitions" (+ "initial", "alphabet_size"): an explicit automaton
//   "nurbs_curve": {"degree", "knots"}
//   "nurbs_surface": {"u": {"degree", "knots"}, "v": {"degree", "knots"}}
//   "product": [SYSTEM, SYSTEM]            (tensor product; default control points a(u) + b(v))
//   "restrict": SYSTEM with "drop_symbols": [..] or "pattern": {"states", "transitions"}
//   "junction": {"a": SURFACE, "b": SURFACE, "ratio", "amplitude", "sides"}   (cifs/junction.h; the
//               sides are "product" or "nurbs_surface" systems with one u automaton; the junction's
//               control points are theirs)
// and optionally "control_points_mm" (replaces the default; [x, y, z] or [x, y, z, w] each, a list of
// rows for products), "scale" and "translate_mm" (applied to the control points). `path` names the
// object in messages. Throws InvalidInput naming the file and JSON path.
Cifs parse_system(const nlohmann::json& value, const std::string& file, const std::string& path);

// Reads a system from a JSON file, or takes a library name when `name_or_file` is one.
Cifs load_system(const std::string& name_or_file);

// The automaton and control points as JSON (states with control point counts, primitives,
// stationary flags and primitive vertices; transitions with matrices; control points).
nlohmann::json system_json(const Cifs& cifs);

// Per symbol of the initial state, the limit point of symbol^ω in mm and, where the attractor is
// smooth there (cifs/automaton.h, FixedPointFrame), its unit tangents (into the primitive) and for
// surfaces the unit normal (first tangent x second); otherwise the reason. The primitives must be
// complete (complete_primitives()).
nlohmann::json initial_frames_json(const Cifs& cifs);

}  // namespace cifs
}  // namespace lacuna
