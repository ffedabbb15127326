#include "voronoi/walls.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

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
  std::vector<int> generator_of_key; // m D^n entries
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
  lattice.generator_of_key.assign(size_t(cells) * m, -1);
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
    lattice.generator_of_key[size_t(k)] = int(i);
    lattice.key[i] = k;
    lattice.z[i] = zz;
  }
  return lattice;
}

// The periodic cells of the starting points (level 0), each face with its neighbour and shift.
std::vector<Cell> shape_cells(const Rules& rules) { return periodic_cells(generate_level(rules, 0)); }

// Every face between two generators of a scaled level that wanted(i, j, shift) asks for (symmetric: the
// same answer from j with -shift), once, from the generator of the lower lattice key: emit(i, j, shift,
// make_facet), make_facet() building the facet around i's wrapped position (only when called) and shift
// the whole periods from i's wrapped copy to the copy of j across the face. Returns how many generators had a face asked for.
template <class Wanted, class Emit>
size_t scan_faces(const Rules& rules, const Level& level, const Lattice& lattice, const std::vector<Cell>& cells,
                  Wanted&& wanted, Emit&& emit) {
  const int n = rules.dimension;
  const double scale = 1.0 / double(lattice.D);
  size_t boundary_generators = 0;
  for (size_t i = 0; i < level.points.size(); ++i) {
    const int shape = level.shapes[i];
    const Cell& cell = cells[size_t(shape)];
    const auto& x = level.points[i];
    const auto& p = rules.points[size_t(shape)];
    bool boundary = false;
    for (size_t f = 0; f < cell.faces.size(); ++f) {
      const Neighbour& nb = cell.across[f];
      std::array<int64_t, 3> zz{0, 0, 0};
      std::array<int, 3> shift{0, 0, 0};
      for (int j = 0; j < n; ++j) {
        const int64_t raw = lattice.z[i][size_t(j)] + nb.shift[size_t(j)];
        zz[size_t(j)] = modulo(raw, lattice.D);
        shift[size_t(j)] = int((raw - zz[size_t(j)]) / lattice.D);
      }
      const int64_t other_key = lattice.key_of(nb.generator, zz);
      const size_t other = size_t(lattice.generator_of_key[size_t(other_key)]);
      if (!wanted(i, other, shift)) continue;
      boundary = true;
      if (other_key < lattice.key[i]) continue;  // the neighbour carries this face
      emit(i, other, shift, [&] {
        std::vector<Point3> facet;
        for (const Point3& v : cell.faces[f]) {
          Point3 q{0, 0, 0};
          for (int j = 0; j < n; ++j) q[size_t(j)] = x[size_t(j)] + (v[size_t(j)] - p[size_t(j)]) * scale;
          facet.push_back(q);
        }
        return facet;
      });
    }
    if (boundary) ++boundary_generators;
  }
  return boundary_generators;
}

}  // namespace

Walls extract_walls(const Rules& rules, const Level& level) {
  const Lattice lattice = make_lattice(rules, level);
  const std::vector<Cell> cells = shape_cells(rules);
  const int n = rules.dimension;
  Walls walls;
  walls.dimension = n;
  walls.points = level.points.size();
  walls.boundary_generators = scan_faces(
      rules, level, lattice, cells,
      [&](size_t i, size_t j, const std::array<int, 3>&) { return level.colours[i] != level.colours[j]; },
      [&](size_t i, size_t j, const std::array<int, 3>&, auto&& make_facet) {
        std::vector<Point3> facet = make_facet();
        walls.measure += facet_measure(facet, n);
        walls.facets.push_back(std::move(facet));
        walls.colours.push_back({level.colours[i], level.colours[j]});
      });
  return walls;
}

RefinedWalls refined_walls(const Rules& rules, int detail, int levels, const std::array<int, 3>& lo,
                           const std::array<int, 3>& hi,
                           const std::function<bool(const std::vector<double>& x, int l)>& refine) {
  if (detail < 0 || levels < 0 || levels > 7)
    throw InvalidInput("voronoi: a refined level needs detail >= 0 and 0 to 7 levels, got " + std::to_string(detail) +
                       " and " + std::to_string(levels));
  const int n = rules.dimension;
  double period_count = 1;
  for (int k = 0; k < 3; ++k) {
    if (hi[size_t(k)] <= lo[size_t(k)] || (k >= n && hi[size_t(k)] - lo[size_t(k)] != 1))
      throw InvalidInput("voronoi: the periods to refine over must be a non-empty box (one period along unused axes)");
    period_count *= double(hi[size_t(k)]) - double(lo[size_t(k)]);
  }
  if (period_count > 1e7) throw ResourceLimit("voronoi: more than 10 000 000 periods to refine over; use a larger period");
  // The fine level with each point's deepest tile (its node of level `levels`, the recursion's order) as
  // its colour.
  const Level fine = refine_level(rules, detail, levels, [](const std::vector<double>&, int) { return true; }, true).level;
  const Lattice lattice = make_lattice(rules, fine);
  const std::vector<Cell> cells = shape_cells(rules);
  // Whole periods from each generator's wrapped position to its unwrapped one (where its tile lies).
  std::vector<std::array<int, 3>> s(fine.points.size(), {0, 0, 0});
  for (size_t i = 0; i < fine.points.size(); ++i)
    for (int k = 0; k < n; ++k)
      s[i][size_t(k)] = int(std::lround(fine.unwrapped[i][size_t(k)] - fine.points[i][size_t(k)]));
  // Faces that can be walls in some copy: between points of different deepest tiles, or of copies of one
  // that meets its own translate (the copies may keep it at different levels). Counted first, so that
  // nothing grows past the bound; a side's anchor is its period plus its reach (-s_i, shift - s_j).
  auto wanted = [&](size_t i, size_t j, const std::array<int, 3>& shift) {
    if (fine.colours[i] != fine.colours[j]) return true;
    for (int k = 0; k < n; ++k)
      if (shift[size_t(k)] != s[j][size_t(k)] - s[i][size_t(k)]) return true;
    return false;
  };
  size_t candidate_count = 0;
  std::array<int, 3> reach_min{0, 0, 0}, reach_max{0, 0, 0};
  const size_t boundary = scan_faces(rules, fine, lattice, cells, wanted,
                                     [&](size_t i, size_t j, const std::array<int, 3>& shift, auto&&) {
                                       ++candidate_count;
                                       for (int k = 0; k < n; ++k) {
                                         const int ri = -s[i][size_t(k)], rj = shift[size_t(k)] - s[j][size_t(k)];
                                         reach_min[size_t(k)] = std::min({reach_min[size_t(k)], ri, rj});
                                         reach_max[size_t(k)] = std::max({reach_max[size_t(k)], ri, rj});
                                       }
                                     });
  if (period_count * double(candidate_count) > 5e7)
    throw ResourceLimit("voronoi: " + std::to_string(int64_t(period_count)) + " periods of up to " +
                        std::to_string(candidate_count) + " walls each are too many; use a larger period");
  // Every copy of the tiling that a side of a face in the periods lies in: anchors lo + reach_min .. hi - 1 +
  // reach_max. The nodes asked (levels < levels) number m (d^n)^l at level l.
  std::array<int, 3> amin{0, 0, 0}, acount{1, 1, 1};
  double anchors_d = 1;
  for (int k = 0; k < n; ++k) {
    amin[size_t(k)] = lo[size_t(k)] + reach_min[size_t(k)];
    acount[size_t(k)] = (hi[size_t(k)] - 1 + reach_max[size_t(k)]) - amin[size_t(k)] + 1;
    anchors_d *= double(acount[size_t(k)]);
  }
  double per_level = double(rules.points.size()), asked_d = 0;
  for (int l = 0; l < levels; ++l) {
    asked_d += per_level;
    per_level *= std::pow(double(rules.d), n);
  }
  if (anchors_d * std::max(asked_d, 1.0) > 2e8 || anchors_d * (asked_d + per_level) > 2e9)
    throw ResourceLimit("voronoi: refining " + std::to_string(int64_t(anchors_d)) + " copies of " +
                        std::to_string(int64_t(asked_d)) + " tiles each is too much; use a larger period or fewer "
                        "refinement levels");
  const int64_t anchors = int64_t(anchors_d);
  // The recursion's nodes of levels 0 .. levels (the tiles a point can end in), in its order (global ids
  // node_offset[l] + j), and each node's parent: a node's children follow it in the next level, as many as
  // its shape's rules.
  std::vector<Level> nodes;
  std::vector<int64_t> node_offset{0};
  for (int l = 0; l <= levels; ++l) {
    nodes.push_back(generate_level(rules, l, true));
    node_offset.push_back(node_offset.back() + int64_t(nodes.back().points.size()));
  }
  std::vector<std::vector<int32_t>> parent(size_t(levels) + 1);
  for (int l = 0; l < levels; ++l) {
    auto& next = parent[size_t(l) + 1];
    for (size_t j = 0; j < nodes[size_t(l)].points.size(); ++j)
      for (size_t c = 0; c < rules.rules[size_t(nodes[size_t(l)].shapes[j])].size(); ++c) next.push_back(int32_t(j));
    if (next.size() != nodes[size_t(l) + 1].points.size()) throw std::logic_error("voronoi: the levels' sizes disagree");
  }
  const int64_t split_nodes = node_offset[size_t(levels)], total_nodes = node_offset.back();
  auto anchor_index = [&](const std::array<int, 3>& a) {
    int64_t index = 0;
    for (int k = n - 1; k >= 0; --k) index = index * acount[size_t(k)] + (a[size_t(k)] - amin[size_t(k)]);
    return index;
  };
  // Whether the copy at anchor a of node j of level l < levels splits: asked once, in parallel.
  std::vector<uint8_t> split(size_t(anchors * split_nodes), 0);
  tbb::parallel_for(int64_t(0), anchors, [&](int64_t index) {
    std::array<int, 3> a{0, 0, 0};
    int64_t rest = index;
    for (int k = 0; k < n; ++k) {
      a[size_t(k)] = amin[size_t(k)] + int(rest % acount[size_t(k)]);
      rest /= acount[size_t(k)];
    }
    std::vector<double> x(static_cast<size_t>(n), 0.0);
    for (int l = 0; l < levels; ++l)
      for (size_t j = 0; j < nodes[size_t(l)].unwrapped.size(); ++j) {
        for (int k = 0; k < n; ++k) x[size_t(k)] = nodes[size_t(l)].unwrapped[j][size_t(k)] + a[size_t(k)];
        split[size_t(index * split_nodes + node_offset[size_t(l)] + int64_t(j))] = refine(x, l) ? 1 : 0;
      }
  });
  // The tile (global node id) point i ends in, in the copy at anchor index ai: its deepest node's ancestors
  // from the top while they split.
  auto tile_of = [&](int64_t ai, size_t i) {
    std::array<int64_t, 8> chain{};
    int64_t j = fine.colours[i];
    for (int l = levels; l >= 0; --l) {
      chain[size_t(l)] = j;
      if (l > 0) j = parent[size_t(l)][size_t(j)];
    }
    for (int l = 0;; ++l)
      if (l == levels || !split[size_t(ai * split_nodes + node_offset[size_t(l)] + chain[size_t(l)])])
        return node_offset[size_t(l)] + chain[size_t(l)];
  };
  struct Candidate {
    uint32_t i, j;
    std::array<int, 3> shift;
    std::vector<Point3> facet;
  };
  std::vector<Candidate> candidates;
  candidates.reserve(candidate_count);
  scan_faces(rules, fine, lattice, cells, wanted,
             [&](size_t i, size_t j, const std::array<int, 3>& shift, auto&& make_facet) {
               candidates.push_back({uint32_t(i), uint32_t(j), shift, make_facet()});
             });
  // Each period's walls: the candidates whose two sides end in different tiles there (copies of one tile
  // that meet have no wall between them, as in the periodic walls).
  std::vector<std::array<int, 3>> periods;
  for (int z2 = lo[2]; z2 < hi[2]; ++z2)
    for (int z1 = lo[1]; z1 < hi[1]; ++z1)
      for (int z0 = lo[0]; z0 < hi[0]; ++z0) periods.push_back({z0, z1, z2});
  std::vector<Walls> per_period(periods.size());
  tbb::parallel_for(size_t(0), periods.size(), [&](size_t q) {
    const std::array<int, 3>& z = periods[q];
    Walls& w = per_period[q];
    for (const Candidate& c : candidates) {
      std::array<int, 3> ai{0, 0, 0}, aj{0, 0, 0};
      for (int k = 0; k < n; ++k) {
        ai[size_t(k)] = z[size_t(k)] - s[c.i][size_t(k)];
        aj[size_t(k)] = z[size_t(k)] + c.shift[size_t(k)] - s[c.j][size_t(k)];
      }
      const int64_t xi = anchor_index(ai), xj = anchor_index(aj);
      const int64_t ti = tile_of(xi, c.i), tj = tile_of(xj, c.j);
      if (ti == tj) continue;
      std::vector<Point3> facet = c.facet;
      for (Point3& v : facet)
        for (int k = 0; k < n; ++k) v[size_t(k)] += z[size_t(k)];
      w.measure += facet_measure(facet, n);
      w.facets.push_back(std::move(facet));
      w.colours.push_back({int(xi * total_nodes + ti), int(xj * total_nodes + tj)});
    }
  });
  RefinedWalls out;
  Walls& walls = out.walls;
  walls.dimension = n;
  walls.points = fine.points.size();  // per period, as extract_walls
  walls.boundary_generators = boundary;
  std::vector<int> instances;
  for (Walls& w : per_period) {
    walls.measure += w.measure;
    for (size_t f = 0; f < w.facets.size(); ++f) {
      walls.facets.push_back(std::move(w.facets[f]));
      walls.colours.push_back(w.colours[f]);
      instances.push_back(w.colours[f].first);
      instances.push_back(w.colours[f].second);
    }
    w = Walls();
  }
  std::sort(instances.begin(), instances.end());
  instances.erase(std::unique(instances.begin(), instances.end()), instances.end());
  out.tiles_per_level.assign(size_t(levels) + 1, 0);
  for (int id : instances) {
    const int64_t node = int64_t(id) % total_nodes;
    const size_t l = size_t(std::upper_bound(node_offset.begin(), node_offset.end(), node) - node_offset.begin()) - 1;
    ++out.tiles_per_level[l];
  }
  return out;
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
