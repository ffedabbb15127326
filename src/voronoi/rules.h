// Fractal partitions from coloured Voronoi diagrams (../shared/spec/fractal-voronoi.md): the substitution
// rules computed once from m starting points on the unit torus [0,1)^n (n = 2 or 3), the point sets P^k they
// generate, and the exact colour measures of the periodic Voronoi diagram of a level. Coordinates are in
// torus units (the torus has side 1); scaling to millimetres is the caller's business.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

namespace lacuna {
namespace voronoi {

// One child in a substitution rule S(r).
struct Rule {
  std::vector<double> offset;  // u: n components, unwrapped (q - r moved by whole periods to the nearest copy)
  int follows = 0;             // 0-based index i of the starting point whose rule the child follows
};

struct Rules {
  int dimension = 2;                        // n: 2 or 3
  int d = 2;                                // lacunarity, >= 2
  std::vector<std::vector<double>> points;  // P^0: m points of n coordinates in [0,1), colour = index
  // rules[r] = S(p(r)), children listed by starting point i ascending, then by a ascending with a_0 varying
  // fastest (a = sum_j a_j d^j); sum_r |rules[r]| = d^n m.
  std::vector<std::vector<Rule>> rules;
  // M (m x m): row r is the rule S(p(r)), column i counts its children that follow rule i. Every column sums
  // to d^n (each point p(i) has d^n children in all), so a = M a / d^n for the limit measures a.
  Eigen::MatrixXd matrix;
  // The limit colour measures: the eigenvector of M for the eigenvalue d^n with non-negative entries summing
  // to 1 (when that eigenvalue is not simple: the limit of (M / d^n)^k applied to the uniform vector).
  std::vector<double> limit_measures;
  // Graph(V^0) == Graph(V^1): the colours whose Voronoi cells share an edge (2D) or a face (3D) are the same
  // at levels 0 and 1; a sufficient condition for every fractal cell to be connected.
  bool graph_connected_condition = false;
};

// Where the children of p(i) are placed before their nearest starting point is looked up.
struct RulesOptions {
  enum class Children {
    kShifted,  // the spec as written: q = p(i) + a/d. P^k then holds coincident points (d = 2: different
               // colours too) and the level measures do not converge to limit_measures.
    kScaled,   // q = (p(i) + a)/d: P^k = (P^0 + Z^n)/d^k, all distinct, m cell shapes, and the level measures
               // converge to limit_measures (the spec's own checks hold).
  };
  Children children = Children::kShifted;
};

// Squared torus distance: sum_j min(|p_j - q_j|, 1 - |p_j - q_j|)^2, for coordinates in [0,1).
double torus_distance_squared(const std::vector<double>& p, const std::vector<double>& q);

// The substitution rules of P^0 (spec "Substitution rules", step 1 as options.children says): nearest points under the
// torus distance with exact comparisons of squared distances, ties to the lower colour. Throws InvalidInput unless n is
// 2 or 3, d >= 2, there is at least one point, every point has n finite coordinates in [0,1) and no two points
// coincide; throws ResourceLimit when d^n m > 1e6 or m > 1000 (M is dense).
Rules make_rules(int n, int d, const std::vector<std::vector<double>>& points, const RulesOptions& options = {});

// m points uniform in [0,1)^n from the project's own deterministic generator (xoshiro256** seeded through
// splitmix64, top 53 bits): the same output for the same seed on every platform. Throws InvalidInput unless
// n >= 1 and m >= 0.
std::vector<std::vector<double>> random_points(int n, int m, uint64_t seed);

// A generated level P^k.
struct Level {
  int dimension = 2;                        // n
  int colour_count = 0;                     // m
  std::vector<std::vector<double>> points;  // wrapped into [0,1)^n, in the order of the spec's Sub recursion
  std::vector<int> colours;                 // 0-based colour (starting point) of each point
  // The starting point whose rule each point followed last: with scaled children the point is
  // (p(shape) + z) / d^k for an integer vector z, so its Voronoi cell is that starting point's cell scaled.
  std::vector<int> shapes;
  // The positions before wrapping (only when asked for): each colour's points form one compact tile around its
  // starting point instead of being scattered over the torus.
  std::vector<std::vector<double>> unwrapped;
};

// P^k by the spec's recursion Sub: (d^n)^k m points. Throws InvalidInput for k < 0 and ResourceLimit when
// the level would hold more than 20 000 000 points.
Level generate_level(const Rules& rules, int k, bool keep_unwrapped = false);

// A tiling of non-uniform density (quasi-periodic tilings: every tile is the union of its children, the
// tiles of the next level scaled by 1/d). A point of P^l carries one tile of level l, the union of the cells
// of its descendants; the tiles of level 0 are the partition's m fractal cells. Starting from them, a tile of
// level l < levels is replaced by its children while refine(x, l) says so, x the tile's generator at its
// unwrapped position (where the compact tile lies: it may be just outside [0,1)^n; wrap it for the torus). Every tile is drawn with `detail` more levels, so the level is generated to detail + levels
// with scaled children, and each of its points is coloured by the tile it ends in: `level.colours` are tile
// indices (colour_count the number of tiles, in the order of the spec's recursion), so walls between colours
// are the walls between tiles, closed across every change of resolution because all of them are faces of one
// Voronoi diagram. Never refining gives generate_level(rules, detail + levels) itself. keep_unwrapped: also
// the positions before wrapping, so each tile is compact around its node (for tile_pieces). Throws
// InvalidInput for detail < 0 or levels < 0 and ResourceLimit as generate_level.
struct RefinedLevel {
  Level level;
  std::vector<int> tile_level;       // per tile: the level it was kept at (0 .. levels)
  std::vector<int> tile_shape;       // per tile: the starting point whose rule its generator follows
  std::vector<int> tile_colour;      // per tile: its starting colour (the level-0 tile it lies in)
  std::vector<int> tiles_per_level;  // how many tiles were kept at each level 0 .. levels
};
RefinedLevel refine_level(const Rules& rules, int detail, int levels,
                          const std::function<bool(const std::vector<double>& x, int l)>& refine,
                          bool keep_unwrapped = false);

// The measure of each colour's union of periodic Voronoi cells at a 2D level, exactly (each cell is the
// torus square around its generator clipped by the bisectors of every generator copy that can reach it), so
// the entries sum to 1 up to rounding. Generators within 1e-12 of each other share their cell equally (the
// recursion places points at the same site by different paths, for d = 2, sometimes with different colours).
// Throws InvalidInput unless the level is 2D with every colour in [0, colour_count).
std::vector<double> cell_measures_2d(const Level& level);

// The same in 3D with convex polyhedron clipping (the torus cube around each generator).
std::vector<double> cell_measures_3d(const Level& level);

// The generator across one face of a periodic Voronoi cell: its index in the level and the whole periods
// added to its wrapped position (the copy whose bisector carries the face).
struct Neighbour {
  int generator = 0;
  std::array<int, 3> shift{0, 0, 0};
};

// The periodic Voronoi cell of one generator, around its wrapped position (it may reach outside [0,1)^n).
struct Cell {
  // 3D: the convex faces, counter-clockwise seen from outside; 2D: the polygon's edges in counter-clockwise
  // order, each as its two end points (third coordinate 0).
  std::vector<std::vector<std::array<double, 3>>> faces;
  std::vector<Neighbour> across;  // one per face
  std::vector<int> coincident;    // other generators at the same site (they share the cell)
};

// Every generator's cell, clipped exactly (see cell_measures_2d). Throws InvalidInput as the cell measures do.
std::vector<Cell> periodic_cells(const Level& level);

// The neighbourhood graph of a level (2D or 3D): the pairs (c1, c2), c1 < c2, of colours whose cells share
// an edge (2D) or a face (3D) of positive size (more than 1e-12 of the torus side, squared in 3D), sorted.
std::vector<std::pair<int, int>> colour_graph(const Level& level);

}  // namespace voronoi
}  // namespace lacuna
