// Space-filling curves on surfaces turned into plain geometry: tubes along the mapped curves (a
// radius per order) and, optionally, the surface itself as a base shell.
#pragma once

#include <string>
#include <vector>

#include "curves/curves.h"
#include "geometry.h"

namespace lacuna {
namespace curves {

struct SweepOptions {
  enum class Kind { kHilbert, kSierpinski, kHilbert3d };
  Kind kind = Kind::kHilbert;
  std::vector<int> orders{1, 2, 3};
  std::vector<double> radii_mm{0.5};  // one per order, or one for all
  MapOptions map;                      // scale (mm per unit of the square), offset, tolerance
  Vec3d center_mm{0, 0, 0};            // added to every point
  double base_thickness_mm = 0;        // > 0: the surface thickened by this much (centred on it)
};

struct Sweep {
  TubeSet tubes;                       // one tube per polyline, closed ones repeat their first point
  std::vector<ThickSurface> base;      // the base shell's surface, when asked for
  uint64_t segments = 0;               // segments of the mapped polylines
};

// Orders written "FROM..TO" (e.g. "1..6") or as a list "3,4,6". Throws InvalidInput (the text and
// what was expected) for anything else, or an empty range.
std::vector<int> parse_orders(const std::string& text);

// The surface names a sweep understands: "plane" (the square at z = 0), "sphere", "cylinder",
// "torus", "cone", "cube"; anything else is given as a map (B-spline or mesh patch).
SurfaceMap plane_map();

// The curves of `options` mapped by `map` (ignored for kHilbert3d, which fills the cube (-1, 1)^3
// scaled and centred), or drawn on the six faces of the cube when `on_cube` is set. Throws
// InvalidInput for radii that do not match the orders.
Sweep sweep_curves(const SweepOptions& options, const SurfaceMap& map, bool on_cube = false);

// The square [-1, 1]^2 mapped by `map` as an n x n grid of quads (two triangles each), scaled by
// `scale` and moved by `center`, with n doubled from 16 until the image of every quad's centre is
// within `tolerance_mm` of the mean of its corners (at most 1024). Triangles of zero area (a cone's
// apex) are left out.
TriMesh tessellate_map(const SurfaceMap& map, double scale, const Vec3d& center_mm, double tolerance_mm);

}  // namespace curves
}  // namespace lacuna
