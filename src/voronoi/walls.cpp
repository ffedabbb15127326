#include "voronoi/walls.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "errors.h"
#include "voronoi/clip.h"

namespace lacuna {
namespace voronoi {
namespace {

using namespace detail;

double facet_measure(const std::vector<Point3>& f, int n) {
  if (n == 2) return std::hypot(f[1][0] - f[0][0], f[1][1] - f[0][1]);
  const V3 a = area_vector(f);
  return std::sqrt(dot3(a, a));
}

// Where every generator of a scaled level sits on the lattice: generator (shape j, z) is (p(j) + z) / D with
// D = d^k, and key = j D^n + z_0 + z_1 D (+ z_2 D^2).
struct Lattice {
  int n = 2;
  int64_t D = 1;
  int64_t cells = 1;                 // D^n
  std::vector<int> colour_of_key;    // m D^n entries
  std::vector<int64_t> key;          // per generator
  std::vector<std::array<int64_t, 3>> z;  // per generator

  int64_t key_of(int shape, const std::array<int64_t, 3>& zz) const {
    int64_t k = 0;
    for (int j = n - 1; j >= 0; --j) k = k * D + zz[size_t(j)];
    return int64_t(shape) * cells + k;
  }
};

int64_t modulo(int64_t a, int64_t b) { return ((a % b) + b) % b; }

Lattice make_lattice(const Rules& rules, const Level& level) {
  const int n = rules.dimension;
  const size_t m = rules.points.size();
  // Colours need not be the starting points' (a refined level colours by tile); shapes must be.
  bool shapes_ok = level.dimension == n && level.shapes.size() == level.points.size() &&
                   level.colours.size() == level.points.size();
  for (size_t i = 0; shapes_ok && i < level.shapes.size(); ++i) shapes_ok = level.shapes[i] >= 0 && size_t(level.shapes[i]) < m;
  if (!shapes_ok) throw InvalidInput("voronoi walls: the level was not generated from these rules");
  Lattice lattice;
  lattice.n = n;
  // |P^k| = m (d^n)^k: find D = d^k.
  const size_t per_shape = level.points.size() / m;
  int64_t D = 1, cells = 1;
  while (cells < int64_t(per_shape)) {
    D *= rules.d;
    cells = 1;
    for (int j = 0; j < n; ++j) cells *= D;
  }
  if (cells * int64_t(m) != int64_t(level.points.size()))
    throw InvalidInput("voronoi walls: the level's size is not m (d^n)^k");
  lattice.D = D;
  lattice.cells = cells;
  lattice.colour_of_key.assign(size_t(cells) * m, -1);
  lattice.key.resize(level.points.size());
  lattice.z.resize(level.points.size());
  for (size_t i = 0; i < level.points.size(); ++i) {
    const int shape = level.shapes[i];
    std::array<int64_t, 3> zz{0, 0, 0};
    for (int j = 0; j < n; ++j) {
      const double t = level.points[i][size_t(j)] * double(D) - rules.points[size_t(shape)][size_t(j)];
      const double r = std::round(t);
      if (std::fabs(t - r) > 1e-6)
        throw InvalidInput("voronoi walls: generator " + std::to_string(i) +
                           " is not on the lattice of scaled children (use children \"scaled\")");
      zz[size_t(j)] = modulo(int64_t(r), D);
    }
    const int64_t k = lattice.key_of(shape, zz);
    if (lattice.colour_of_key[size_t(k)] != -1)
      throw InvalidInput("voronoi walls: two generators share lattice site " + std::to_string(k) +
                         " (use children \"scaled\")");
    lattice.colour_of_key[size_t(k)] = level.colours[i];
    lattice.key[i] = k;
    lattice.z[i] = zz;
  }
  return lattice;
}

// The periodic cells of the starting points (level 0), each face with its neighbour and shift.
std::vector<Cell> shape_cells(const Rules& rules) { return periodic_cells(generate_level(rules, 0)); }

}  // namespace

Walls extract_walls(const Rules& rules, const Level& level) {
  const Lattice lattice = make_lattice(rules, level);
  const std::vector<Cell> cells = shape_cells(rules);
  const int n = rules.dimension;
  const double scale = 1.0 / double(lattice.D);
  Walls walls;
  walls.dimension = n;
  walls.points = level.points.size();
  for (size_t i = 0; i < level.points.size(); ++i) {
    const int shape = level.shapes[i];
    const Cell& cell = cells[size_t(shape)];
    const int colour = level.colours[i];
    const auto& x = level.points[i];
    const auto& p = rules.points[size_t(shape)];
    bool boundary = false;
    for (size_t f = 0; f < cell.faces.size(); ++f) {
      const Neighbour& nb = cell.across[f];
      std::array<int64_t, 3> zz{0, 0, 0};
      for (int j = 0; j < n; ++j) zz[size_t(j)] = modulo(lattice.z[i][size_t(j)] + nb.shift[size_t(j)], lattice.D);
      const int64_t other_key = lattice.key_of(nb.generator, zz);
      const int other = lattice.colour_of_key[size_t(other_key)];
      if (other == colour) continue;
      boundary = true;
      if (other_key < lattice.key[i]) continue;  // the neighbour carries this wall
      std::vector<Point3> facet;
      for (const Point3& v : cell.faces[f]) {
        Point3 q{0, 0, 0};
        for (int j = 0; j < n; ++j) q[size_t(j)] = x[size_t(j)] + (v[size_t(j)] - p[size_t(j)]) * scale;
        facet.push_back(q);
      }
      walls.measure += facet_measure(facet, n);
      walls.facets.push_back(std::move(facet));
      walls.colours.push_back({colour, other});
    }
    if (boundary) ++walls.boundary_generators;
  }
  return walls;
}

Walls walls_by_clipping(const Level& level) {
  const std::vector<Cell> cells = periodic_cells(level);
  Walls walls;
  walls.dimension = level.dimension;
  walls.points = level.points.size();
  for (size_t i = 0; i < cells.size(); ++i) {
    const int colour = level.colours[i];
    bool boundary = false;
    for (size_t f = 0; f < cells[i].faces.size(); ++f) {
      const int t = cells[i].across[f].generator;
      const int other = level.colours[size_t(t)];
      if (other == colour) continue;
      boundary = true;
      if (size_t(t) < i) continue;
      walls.measure += facet_measure(cells[i].faces[f], level.dimension);
      walls.facets.push_back(cells[i].faces[f]);
      walls.colours.push_back({colour, other});
    }
    if (boundary) ++walls.boundary_generators;
  }
  return walls;
}

TriMesh wall_triangles(const Walls& walls, double period_mm, const Vec3d& origin_mm, const std::array<int, 3>& lo,
                       const std::array<int, 3>& hi) {
  if (walls.dimension != 3) throw InvalidInput("voronoi walls: only 3D walls are triangulated");
  TriMesh mesh;
  for (int tz = lo[2]; tz < hi[2]; ++tz)
    for (int ty = lo[1]; ty < hi[1]; ++ty)
      for (int tx = lo[0]; tx < hi[0]; ++tx)
        for (const auto& facet : walls.facets) {
          const uint32_t first = uint32_t(mesh.positions_mm.size());
          for (const Point3& p : facet)
            mesh.positions_mm.push_back(origin_mm + Vec3d{p[0] + tx, p[1] + ty, p[2] + tz} * period_mm);
          for (uint32_t i = 1; i + 1 < facet.size(); ++i) mesh.triangles.push_back({first, first + i, first + i + 1});
        }
  return mesh;
}

std::vector<ConvexPiece> tile_pieces(const Rules& rules, const Level& level, int colour, double half_gap) {
  std::vector<char> keep(size_t(std::max(level.colour_count, colour + 1)), 0);
  if (colour >= 0) keep[size_t(colour)] = 1;
  return tile_pieces(rules, level, keep, half_gap);
}

std::vector<ConvexPiece> tile_pieces(const Rules& rules, const Level& level, const std::vector<char>& keep,
                                     double half_gap) {
  if (level.unwrapped.size() != level.points.size())
    throw InvalidInput("voronoi tiles: the level needs its unwrapped positions (generate_level(..., true))");
  if (!(half_gap >= 0)) throw InvalidInput("voronoi tiles: the gap must be >= 0");
  const Lattice lattice = make_lattice(rules, level);
  const std::vector<Cell> cells = shape_cells(rules);
  const int n = rules.dimension;
  const double scale = 1.0 / double(lattice.D);
  std::vector<ConvexPiece> pieces;
  for (size_t i = 0; i < level.points.size(); ++i) {
    const int colour = level.colours[i];
    if (colour < 0 || size_t(colour) >= keep.size() || !keep[size_t(colour)]) continue;
    const int shape = level.shapes[i];
    const Cell& cell = cells[size_t(shape)];
    const auto& u = level.unwrapped[i];
    const auto& p = rules.points[size_t(shape)];
    // Start from the cell's bounding box grown by a tenth and cut it with the cell's (moved) face planes.
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int j = 0; j < n; ++j) {
      lo[j] = 1e300;
      hi[j] = -1e300;
    }
    for (const auto& face : cell.faces)
      for (const Point3& v : face)
        for (int j = 0; j < n; ++j) {
          const double q = u[size_t(j)] + (v[size_t(j)] - p[size_t(j)]) * scale;
          lo[j] = std::min(lo[j], q);
          hi[j] = std::max(hi[j], q);
        }
    for (int j = 0; j < n; ++j) {
      const double grow = 0.1 * (hi[j] - lo[j]);
      lo[j] -= grow;
      hi[j] += grow;
    }
    Polygon2 poly2;
    Polyhedron poly3;
    if (n == 2) {
      poly2.v = {{lo[0], lo[1]}, {hi[0], lo[1]}, {hi[0], hi[1]}, {lo[0], hi[1]}};
      poly2.label.assign(4, -1);
    } else {
      poly3.faces = {{{lo[0], lo[1], lo[2]}, {lo[0], hi[1], lo[2]}, {lo[0], hi[1], hi[2]}, {lo[0], lo[1], hi[2]}},
                     {{hi[0], lo[1], lo[2]}, {hi[0], hi[1], lo[2]}, {hi[0], hi[1], hi[2]}, {hi[0], lo[1], hi[2]}},
                     {{lo[0], lo[1], lo[2]}, {hi[0], lo[1], lo[2]}, {hi[0], lo[1], hi[2]}, {lo[0], lo[1], hi[2]}},
                     {{lo[0], hi[1], lo[2]}, {hi[0], hi[1], lo[2]}, {hi[0], hi[1], hi[2]}, {lo[0], hi[1], hi[2]}},
                     {{lo[0], lo[1], lo[2]}, {hi[0], lo[1], lo[2]}, {hi[0], hi[1], lo[2]}, {lo[0], hi[1], lo[2]}},
                     {{lo[0], lo[1], hi[2]}, {hi[0], lo[1], hi[2]}, {hi[0], hi[1], hi[2]}, {lo[0], hi[1], hi[2]}}};
      poly3.label.assign(6, -1);
    }
    for (size_t f = 0; f < cell.faces.size(); ++f) {
      const Neighbour& nb = cell.across[f];
      std::array<int64_t, 3> zz{0, 0, 0};
      V3 r{0, 0, 0};
      double length2 = 0;
      for (int j = 0; j < n; ++j) {
        zz[size_t(j)] = modulo(lattice.z[i][size_t(j)] + nb.shift[size_t(j)], lattice.D);
        r[size_t(j)] = (rules.points[size_t(nb.generator)][size_t(j)] + nb.shift[size_t(j)] - p[size_t(j)]) * scale;
        length2 += r[size_t(j)] * r[size_t(j)];
      }
      const int other = lattice.colour_of_key[size_t(lattice.key_of(nb.generator, zz))];
      const double length = std::sqrt(length2);
      V3 normal{r[0] / length, r[1] / length, r[2] / length};
      double c = 0;
      for (int j = 0; j < n; ++j) c += normal[size_t(j)] * (u[size_t(j)] + r[size_t(j)] / 2);
      if (other != colour) c -= half_gap;
      if (n == 2)
        clip(poly2, normal[0], normal[1], c, int(f));
      else
        clip(poly3, normal, c, int(f));
    }
    ConvexPiece piece;
    if (n == 2) {
      if (poly2.v.size() < 3 || !(area(poly2) > 0)) continue;
      std::vector<Point3> loop;
      for (const V2& v : poly2.v) loop.push_back({v[0], v[1], 0.0});
      piece.faces.push_back(std::move(loop));
    } else {
      if (poly3.faces.size() < 4) continue;
      V3 inside{0, 0, 0};
      size_t count = 0;
      for (const auto& face : poly3.faces)
        for (const V3& v : face) {
          for (int j = 0; j < 3; ++j) inside[size_t(j)] += v[size_t(j)];
          ++count;
        }
      for (double& c : inside) c /= double(count);
      if (!(volume(poly3, inside) > 1e-30)) continue;
      piece.faces = std::move(poly3.faces);
    }
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

}  // namespace voronoi
}  // namespace lacuna
