// The walls of a fractal Voronoi partition (the surfaces of its fractal cells) and the convex pieces of its
// tiles, in torus units. With scaled children a level is P^0 scaled by 1/d^k and repeated on the lattice
// Z^n / d^k, so its periodic Voronoi diagram has only m distinct cells: those of the starting points on the
// torus, scaled. extract_walls uses that: it computes the m cells once and visits every generator only to
// look up the colours across its faces, so a generator whose neighbours all share its colour costs a few
// lookups and no geometry (the saving in ../shared/spec/fractal-voronoi.md).
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "geometry.h"
#include "voronoi/rules.h"

namespace lacuna {
namespace voronoi {

using Point3 = std::array<double, 3>;

struct Walls {
  int dimension = 2;
  // 3D: the convex facets between cells of different colours, counter-clockwise seen from the side of the
  // first colour of the pair; 2D: the segments (two points, third coordinate 0) with that colour on their
  // left. Each wall once, around the wrapped position of the generator that carries it.
  std::vector<std::vector<Point3>> facets;
  std::vector<std::pair<int, int>> colours;  // per facet: (colour behind it, colour in front of it)
  size_t points = 0;               // generators in the level
  size_t boundary_generators = 0;  // generators with a neighbour of another colour; the others were skipped
  double measure = 0;              // total wall length (2D) or area (3D), torus units
};

// The walls of a level generated from `rules` with scaled children (RulesOptions::Children::kScaled). Throws
// InvalidInput when the level was not made that way (a point is not (p(shape) + z) / d^k).
Walls extract_walls(const Rules& rules, const Level& level);

// The same walls from every generator's own clipped cell (periodic_cells): the reference for extract_walls,
// valid for any level, at the cost of computing every cell.
Walls walls_by_clipping(const Level& level);

// A refined tiling (refine_level) laid over the periods [lo, hi) of each axis (one period along axes past the
// dimension) with every copy of a tile refined on its own: the copy anchored at period a of a tile whose
// generator's unwrapped position is u splits while refine(u + a, l) says so, so a field is read where each
// tile lies instead of repeating the first period's choices. The walls are the faces of the level
// detail + levels between points of different tiles (as in refine_level, copies of one tile that meet
// have none between them); facets in torus units with their periods added (draw them over the single
// period [0, 1)), colours numbering the tile copies.
// tiles_per_level counts the copies, per level kept, that have a wall in the periods. With a refine that
// does not depend on the anchor, every period holds the walls of refine_level's level (tested); `points` and
// `boundary_generators` are per period, `facets` and `measure` those of all periods. Throws
// InvalidInput for negative levels, more than 7 or an empty box; ResourceLimit (before allocating them) when
// the periods exceed 1e7, the periods times the faces between deepest tiles 5e7, the copies times the tiles
// asked 2e8 (times all tiles 2e9), or the level the limit of generate_level.
struct RefinedWalls {
  Walls walls;
  std::vector<int> tiles_per_level;
};
RefinedWalls refined_walls(const Rules& rules, int detail, int levels, const std::array<int, 3>& lo,
                           const std::array<int, 3>& hi,
                           const std::function<bool(const std::vector<double>& x, int l)>& refine);

// The 3D walls repeated over the periods [lo, hi) of each axis, as triangles (a fan per facet) in mm:
// x_mm = origin_mm + period_mm x. Throws InvalidInput for 2D walls.
TriMesh wall_triangles(const Walls& walls, double period_mm, const Vec3d& origin_mm, const std::array<int, 3>& lo,
                       const std::array<int, 3>& hi);

// A convex piece of a tile: 3D, faces as vertex loops (each face's corners listed on their own, not shared);
// 2D, one face: the polygon counter-clockwise (third coordinate 0).
struct ConvexPiece {
  std::vector<std::vector<Point3>> faces;
};

// The tile of `colour` at level k, made compact: the cells of its generators at their unwrapped positions
// (level.unwrapped, see generate_level), with every face towards another colour moved inwards by `half_gap`
// (torus units), so that neighbouring tiles keep a clearance of 2 half_gap. Cells that the gap swallows are
// left out. Throws InvalidInput as extract_walls does, or when the level has no unwrapped positions.
std::vector<ConvexPiece> tile_pieces(const Rules& rules, const Level& level, int colour, double half_gap);
// The same for every colour c with keep[c] (keep has level.colour_count entries) in one pass over the level,
// the pieces in the level's point order.
std::vector<ConvexPiece> tile_pieces(const Rules& rules, const Level& level, const std::vector<char>& keep,
                                     double half_gap);

}  // namespace voronoi
}  // namespace lacuna
