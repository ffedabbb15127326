// Motif outlines from files: a JSON list of [x, y] points ({"polygon": [...]} too) or an SVG path
// of straight segments, for `lacuna fill pattern --motif FILE` and a fill input's {"file": ...}.
#pragma once

#include <string>
#include <vector>

#include "fill/fill.h"
#include "geometry.h"

namespace lacuna {
namespace fill {

// The points of one closed SVG path of straight segments: the "d" attribute's M, L, H, V and Z
// commands, absolute and relative, with implicit line-tos after a move-to. Throws InvalidInput
// naming `where` and the character for a curve or arc command (C, S, Q, T, A: not a polygon), a
// second sub-path, a malformed number or no point at all.
std::vector<Vec2d> svg_path_points(const std::string& d, const std::string& where);

// The outline in a file: by its extension, .json (a list of [x, y] points, or an object whose
// "polygon" is one) or .svg (the first <path> element's "d"; SVG's y axis points down, so y is
// negated). Throws IoError when the file cannot be read and InvalidInput naming the file and what
// is wrong with it; the outline is checked as polygon_motif() does.
std::vector<Vec2d> read_motif_outline(const std::string& path);

// Whether a motif name is a file name read_motif_outline() takes (it ends in .json or .svg, either case).
bool names_motif_file(const std::string& name);
// The motif of the outline in a file: polygon_motif(read_motif_outline(path)), its symmetry detected.
Motif2 motif_from_file(const std::string& path);

}  // namespace fill
}  // namespace lacuna
