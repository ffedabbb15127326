#include "voronoi/rules.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <set>
#include <stdexcept>
#include <string>

#include "errors.h"
#include "util/random.h"
#include "voronoi/clip.h"

namespace lacuna {
namespace voronoi {
namespace {

constexpr double kMaxRuleChildren = 1e6;
constexpr int kMaxStartingPoints = 1000;
constexpr double kMaxLevelPoints = 2e7;
// Generators closer than this (torus units) are one site: rounding separates copies that the recursion
// places at the same point by different paths.
constexpr double kCoincident = 1e-12;

double wrap(double x) {
  double w = x - std::floor(x);
  // x slightly below an integer rounds up to exactly 1.
  return w >= 1 ? 0.0 : w;
}

int nearest_point(const std::vector<std::vector<double>>& points, const std::vector<double>& q) {
  int best = 0;
  double best_d2 = torus_distance_squared(points[0], q);
  for (size_t i = 1; i < points.size(); ++i) {
    const double d2 = torus_distance_squared(points[i], q);
    if (d2 < best_d2) {  // strict: a tie keeps the lower colour
      best_d2 = d2;
      best = int(i);
    }
  }
  return best;
}

// The limit of Q^s u for the lazy column-stochastic Q = (I + M / d^n) / 2 and u uniform: the eigenvector of
// M for d^n (the lazy chain is aperiodic, so this converges even when M is periodic). Q is squared until it
// stops changing.
std::vector<double> perron_vector(const Eigen::MatrixXd& matrix, double dn) {
  const Eigen::Index m = matrix.rows();
  Eigen::MatrixXd q = 0.5 * (Eigen::MatrixXd::Identity(m, m) + matrix / dn);
  for (int s = 0; s < 64; ++s) {
    Eigen::MatrixXd q2 = q * q;
    const double change = (q2 - q).cwiseAbs().maxCoeff();
    q.swap(q2);
    if (change <= 1e-16) break;
  }
  Eigen::VectorXd a = q * Eigen::VectorXd::Constant(m, 1.0 / double(m));
  a = a.cwiseMax(0.0);
  a /= a.sum();
  // A few plain steps remove the rounding left by the squarings (M a / d^n keeps the sum: columns sum to d^n).
  for (int s = 0; s < 4; ++s) a = 0.5 * (a + matrix * a / dn);
  const double residual = (matrix * a - dn * a).cwiseAbs().maxCoeff();
  if (!(residual <= 1e-9 * dn))
    throw std::logic_error("voronoi: the limit measures are not an eigenvector of M for d^n (residual " +
                           message_number(residual) + ")");
  return std::vector<double>(a.data(), a.data() + m);
}

// ---- periodic Voronoi cells by clipping ----

// A uniform grid of g^n buckets over the torus.
struct Grid {
  int n = 2;
  int g = 1;
  std::vector<int> start;  // bucket b holds order[start[b] .. start[b + 1])
  std::vector<int> order;

  int cell_of(double x) const { return std::min(g - 1, int(x * g)); }
};

Grid make_grid(const Level& level) {
  Grid grid;
  grid.n = level.dimension;
  const double count = double(level.points.size());
  grid.g = std::max(1, int(std::ceil(std::pow(count / 2, 1.0 / grid.n))));
  size_t buckets = 1;
  for (int j = 0; j < grid.n; ++j) buckets *= size_t(grid.g);
  std::vector<int> bucket(level.points.size());
  grid.start.assign(buckets + 1, 0);
  for (size_t i = 0; i < level.points.size(); ++i) {
    int b = 0;
    for (int j = grid.n - 1; j >= 0; --j) b = b * grid.g + grid.cell_of(level.points[i][size_t(j)]);
    bucket[i] = b;
    ++grid.start[size_t(b) + 1];
  }
  for (size_t b = 0; b < buckets; ++b) grid.start[b + 1] += grid.start[b];
  grid.order.resize(level.points.size());
  std::vector<int> fill(grid.start.begin(), grid.start.end() - 1);
  for (size_t i = 0; i < level.points.size(); ++i) grid.order[size_t(fill[size_t(bucket[i])]++)] = int(i);
  return grid;
}

int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// Calls visit(t, shift) for every generator t in the unwrapped grid cells at Chebyshev distance exactly
// `ring` from `home` (shift: the whole periods added to t's wrapped position).
template <class Visit>
void visit_ring(const Grid& grid, const std::array<int, 3>& home, int ring, Visit&& visit) {
  const int n = grid.n;
  std::array<int, 3> offset{-ring, -ring, n == 3 ? -ring : 0};
  for (;;) {
    int chebyshev = 0;
    for (int j = 0; j < n; ++j) chebyshev = std::max(chebyshev, std::abs(offset[size_t(j)]));
    if (chebyshev == ring) {
      std::array<double, 3> shift{0, 0, 0};
      int b = 0;
      for (int j = n - 1; j >= 0; --j) {
        const int u = home[size_t(j)] + offset[size_t(j)];
        const int period = floor_div(u, grid.g);
        shift[size_t(j)] = period;
        b = b * grid.g + (u - period * grid.g);
      }
      for (int s = grid.start[size_t(b)]; s < grid.start[size_t(b) + 1]; ++s) visit(grid.order[size_t(s)], shift);
    }
    int j = 0;
    while (j < n && offset[size_t(j)] == ring) offset[size_t(j++)] = -ring;
    if (j == n) return;
    ++offset[size_t(j)];
  }
}

using namespace detail;

void check_level(const Level& level, int n) {
  if (level.dimension != n)
    throw InvalidInput("voronoi: a " + std::to_string(level.dimension) + "D level passed to the " + std::to_string(n) +
                       "D cell measure");
  if (level.colours.size() != level.points.size()) throw InvalidInput("voronoi: a level needs one colour per point");
  for (size_t i = 0; i < level.points.size(); ++i) {
    if (level.colours[i] < 0 || level.colours[i] >= level.colour_count)
      throw InvalidInput("voronoi: point " + std::to_string(i) + " has colour " + std::to_string(level.colours[i]) +
                         " outside [0, " + std::to_string(level.colour_count) + ")");
    if (level.points[i].size() != size_t(n))
      throw InvalidInput("voronoi: point " + std::to_string(i) + " does not have " + std::to_string(n) +
                         " coordinates");
    for (double x : level.points[i])
      if (!(x >= 0 && x < 1)) throw InvalidInput("voronoi: point " + std::to_string(i) + " lies outside [0,1)^n");
  }
}

// The periodic Voronoi cell of one generator, by clipping the torus box around it with the bisectors of the
// generator copies in growing rings of grid buckets. Every unprocessed copy lies at least ring / g from the
// generator after rings 0 .. ring (the generator's bucket is at least that far inside the block of scanned
// buckets), so its bisector lies at least ring / (2 g) away and cannot cut a cell whose farthest vertex is
// nearer: the cell is exact when the loop stops.
struct CellWork {
  Polygon2 poly2;                       // n = 2
  Polyhedron poly3;                     // n = 3
  std::vector<Neighbour> neighbours;    // the labels of poly2 / poly3 index this
  std::vector<int> coincident;          // other generators at the same place (the construction makes them for d = 2)
};

void build_cell(const Level& level, const Grid& grid, size_t self, CellWork& w) {
  const int n = level.dimension;
  const double h = 1.0 / grid.g;
  const auto& pts = level.points;
  const auto& x = pts[self];
  std::array<int, 3> home{0, 0, 0};
  for (int j = 0; j < n; ++j) home[size_t(j)] = grid.cell_of(x[size_t(j)]);
  w.coincident.clear();
  w.neighbours.clear();
  const int me = int(self);
  // The box's faces are the bisectors with the generator's own copies one period away.
  if (n == 2) {
    w.poly2.v = {{x[0] - 0.5, x[1] - 0.5}, {x[0] + 0.5, x[1] - 0.5}, {x[0] + 0.5, x[1] + 0.5}, {x[0] - 0.5, x[1] + 0.5}};
    w.neighbours = {{me, {0, -1, 0}}, {me, {1, 0, 0}}, {me, {0, 1, 0}}, {me, {-1, 0, 0}}};
    w.poly2.label = {0, 1, 2, 3};
  } else {
    const double x0 = x[0] - 0.5, x1 = x[0] + 0.5, y0 = x[1] - 0.5, y1 = x[1] + 0.5, z0 = x[2] - 0.5, z1 = x[2] + 0.5;
    w.poly3.faces = {{{x0, y0, z0}, {x0, y1, z0}, {x0, y1, z1}, {x0, y0, z1}},
                     {{x1, y0, z0}, {x1, y1, z0}, {x1, y1, z1}, {x1, y0, z1}},
                     {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, z1}, {x0, y0, z1}},
                     {{x0, y1, z0}, {x1, y1, z0}, {x1, y1, z1}, {x0, y1, z1}},
                     {{x0, y0, z0}, {x1, y0, z0}, {x1, y1, z0}, {x0, y1, z0}},
                     {{x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1}}};
    w.neighbours = {{me, {-1, 0, 0}}, {me, {1, 0, 0}}, {me, {0, -1, 0}},
                    {me, {0, 1, 0}},  {me, {0, 0, -1}}, {me, {0, 0, 1}}};
    w.poly3.label = {0, 1, 2, 3, 4, 5};
  }
  for (int ring = 0;; ++ring) {
    visit_ring(grid, home, ring, [&](int t, const std::array<double, 3>& shift) {
      if (size_t(t) == self) return;
      std::array<double, 3> y{0, 0, 0}, normal{0, 0, 0};
      double c = 0;
      double length2 = 0;
      for (int j = 0; j < n; ++j) {
        y[size_t(j)] = pts[size_t(t)][size_t(j)] + shift[size_t(j)];
        normal[size_t(j)] = y[size_t(j)] - x[size_t(j)];
        c += normal[size_t(j)] * (y[size_t(j)] + x[size_t(j)]) / 2;
        length2 += normal[size_t(j)] * normal[size_t(j)];
      }
      if (length2 <= kCoincident * kCoincident) {
        if (std::find(w.coincident.begin(), w.coincident.end(), t) == w.coincident.end()) w.coincident.push_back(t);
        return;
      }
      const int label = int(w.neighbours.size());
      w.neighbours.push_back({t, {int(shift[0]), int(shift[1]), int(shift[2])}});
      const bool cut = n == 2 ? clip(w.poly2, normal[0], normal[1], c, label) : clip(w.poly3, normal, c, label);
      if (!cut) w.neighbours.pop_back();
    });
    double r2 = 0;
    if (n == 2) {
      for (const V2& p : w.poly2.v) r2 = std::max(r2, (p[0] - x[0]) * (p[0] - x[0]) + (p[1] - x[1]) * (p[1] - x[1]));
    } else {
      const V3 xs{x[0], x[1], x[2]};
      for (const auto& face : w.poly3.faces)
        for (const V3& p : face) r2 = std::max(r2, dot3(sub3(p, xs), sub3(p, xs)));
    }
    // The 1e-12 margin covers a generator that rounding placed in a neighbouring bucket.
    if (2 * std::sqrt(r2) + 1e-12 <= ring * h) break;
  }
}

struct CellScan {
  std::vector<double> measures;         // per colour
  std::set<std::pair<int, int>> graph;  // colour pairs sharing a wall
};

CellScan scan_cells(const Level& level, int n, bool want_graph) {
  check_level(level, n);
  const Grid grid = make_grid(level);
  CellScan scan;
  scan.measures.assign(size_t(level.colour_count), 0.0);
  CellWork w;
  for (size_t self = 0; self < level.points.size(); ++self) {
    build_cell(level, grid, self, w);
    const auto& x = level.points[self];
    const int colour = level.colours[self];
    const double share = 1.0 / double(w.coincident.size() + 1);
    auto other_colour = [&](int label) { return level.colours[size_t(w.neighbours[size_t(label)].generator)]; };
    for (int t : w.coincident) {
      const int other = level.colours[size_t(t)];
      if (want_graph && other != colour) scan.graph.insert({std::min(colour, other), std::max(colour, other)});
    }
    if (n == 2) {
      scan.measures[size_t(colour)] += share * area(w.poly2);
      if (want_graph)
        for (size_t i = 0; i < w.poly2.v.size(); ++i) {
          const int other = other_colour(w.poly2.label[i]);
          const V2& p = w.poly2.v[i];
          const V2& q = w.poly2.v[(i + 1) % w.poly2.v.size()];
          if (other != colour && std::hypot(q[0] - p[0], q[1] - p[1]) > 1e-12)
            scan.graph.insert({std::min(colour, other), std::max(colour, other)});
        }
    } else {
      scan.measures[size_t(colour)] += share * volume(w.poly3, {x[0], x[1], x[2]});
      if (want_graph)
        for (size_t i = 0; i < w.poly3.faces.size(); ++i) {
          const int other = other_colour(w.poly3.label[i]);
          const V3 a = area_vector(w.poly3.faces[i]);
          if (other != colour && std::sqrt(dot3(a, a)) > 1e-12)
            scan.graph.insert({std::min(colour, other), std::max(colour, other)});
        }
    }
  }
  return scan;
}

Level level_zero(const Rules& rules) {
  Level level;
  level.dimension = rules.dimension;
  level.colour_count = int(rules.points.size());
  level.points = rules.points;
  for (size_t i = 0; i < rules.points.size(); ++i) level.colours.push_back(int(i));
  level.shapes = level.colours;
  return level;
}

}  // namespace

double torus_distance_squared(const std::vector<double>& p, const std::vector<double>& q) {
  double sum = 0;
  for (size_t j = 0; j < p.size(); ++j) {
    const double a = std::fabs(p[j] - q[j]);
    const double t = std::min(a, 1 - a);
    sum += t * t;
  }
  return sum;
}

Rules make_rules(int n, int d, const std::vector<std::vector<double>>& points, const RulesOptions& options) {
  if (n != 2 && n != 3) throw InvalidInput("voronoi: the dimension must be 2 or 3, got " + std::to_string(n));
  if (d < 2) throw InvalidInput("voronoi: the lacunarity d must be at least 2, got " + std::to_string(d));
  const size_t m = points.size();
  if (m == 0) throw InvalidInput("voronoi: at least one starting point is needed");
  const double dn_real = std::pow(double(d), n);
  if (dn_real * double(m) > kMaxRuleChildren)
    throw ResourceLimit("voronoi: d^n m = " + message_number(dn_real * double(m)) + " rule children exceed the " +
                        "limit of 1e6; use fewer points or a smaller d");
  if (m > size_t(kMaxStartingPoints))
    throw ResourceLimit("voronoi: " + std::to_string(m) + " starting points exceed the limit of " +
                        std::to_string(kMaxStartingPoints) + " (the rule matrix is dense)");
  for (size_t i = 0; i < m; ++i) {
    if (points[i].size() != size_t(n))
      throw InvalidInput("voronoi: starting point " + std::to_string(i) + " has " + std::to_string(points[i].size()) +
                         " coordinates, expected " + std::to_string(n));
    for (int j = 0; j < n; ++j) {
      const double x = points[i][size_t(j)];
      if (!(x >= 0 && x < 1))
        throw InvalidInput("voronoi: coordinate " + std::to_string(j) + " of starting point " + std::to_string(i) +
                           " is " + std::to_string(x) + ", outside [0, 1)");
    }
  }
  for (size_t i = 0; i < m; ++i)
    for (size_t k = i + 1; k < m; ++k)
      if (torus_distance_squared(points[i], points[k]) == 0)
        throw InvalidInput("voronoi: starting point " + std::to_string(k) + " coincides with starting point " +
                           std::to_string(i));

  Rules rules;
  rules.dimension = n;
  rules.d = d;
  rules.points = points;
  rules.rules.assign(m, {});
  rules.matrix = Eigen::MatrixXd::Zero(Eigen::Index(m), Eigen::Index(m));
  const int dn = int(dn_real);
  std::vector<double> q(static_cast<size_t>(n));
  for (size_t i = 0; i < m; ++i)
    for (int t = 0; t < dn; ++t) {
      int digits = t;
      for (int j = 0; j < n; ++j) {
        const int a = digits % d;
        digits /= d;
        if (options.children == RulesOptions::Children::kScaled) {
          q[size_t(j)] = wrap((points[i][size_t(j)] + double(a)) / d);  // rounding can reach 1
        } else {
          double x = points[i][size_t(j)] + double(a) / d;
          if (x >= 1) x -= 1;  // exact (Sterbenz): x is in [1, 2)
          q[size_t(j)] = x;
        }
      }
      const int r = nearest_point(points, q);
      Rule rule;
      rule.follows = int(i);
      rule.offset.resize(size_t(n));
      for (int j = 0; j < n; ++j) {
        const double qj = q[size_t(j)], rj = points[size_t(r)][size_t(j)];
        rule.offset[size_t(j)] = qj - rj + std::floor(rj - qj + 0.5);
      }
      rules.rules[size_t(r)].push_back(std::move(rule));
      rules.matrix(Eigen::Index(r), Eigen::Index(i)) += 1;
    }
  rules.limit_measures = perron_vector(rules.matrix, dn_real);

  const Level zero = level_zero(rules);
  const Level one = generate_level(rules, 1);
  rules.graph_connected_condition = colour_graph(zero) == colour_graph(one);
  return rules;
}

std::vector<std::vector<double>> random_points(int n, int m, uint64_t seed) {
  if (n < 1 || m < 0)
    throw InvalidInput("voronoi: random_points needs n >= 1 and m >= 0, got n = " + std::to_string(n) +
                       ", m = " + std::to_string(m));
  Random random(seed);
  std::vector<std::vector<double>> points(static_cast<size_t>(m), std::vector<double>(static_cast<size_t>(n)));
  for (auto& p : points)
    for (double& x : p) x = random.uniform();
  return points;
}

namespace {

// The Sub recursion of the spec, refining selectively: a node of level i is kept as a tile when i == levels or
// refine(x, i) is false (levels = 0: every starting point is one tile and its colour, the plain level), and
// every tile's generators are its descendants at level `last`, coloured by the tile.
struct Refiner {
  const Rules& rules;
  int levels, last;
  const std::function<bool(const std::vector<double>&, int)>* refine;  // null when levels == 0
  bool keep_unwrapped;
  std::vector<double> scale;
  RefinedLevel out;

  // The node of level i at p (unwrapped), following rule c, of starting colour s, in tile `tile` (-1: refined
  // so far, not yet a tile).
  void visit(int i, int s, int c, const std::vector<double>& p, int tile) {
    if (tile < 0) {
      if (i == levels || !(*refine)(p, i)) {
        tile = int(out.tile_level.size());
        out.tile_level.push_back(i);
        out.tile_shape.push_back(c);
        out.tile_colour.push_back(s);
        ++out.tiles_per_level[size_t(i)];
      }
    }
    if (i < last) {
      std::vector<double> child(p.size());
      for (const Rule& rule : rules.rules[size_t(c)]) {
        for (size_t j = 0; j < p.size(); ++j) child[j] = p[j] + rule.offset[j] * scale[size_t(i)];
        visit(i + 1, s, rule.follows, child, tile);
      }
      return;
    }
    std::vector<double> q(p.size());
    for (size_t j = 0; j < p.size(); ++j) q[j] = wrap(p[j]);
    out.level.points.push_back(std::move(q));
    out.level.colours.push_back(tile);
    out.level.shapes.push_back(c);
    if (keep_unwrapped) out.level.unwrapped.push_back(p);
  }
};

RefinedLevel refined(const Rules& rules, int detail, int levels,
                     const std::function<bool(const std::vector<double>&, int)>* refine, bool keep_unwrapped) {
  const int last = detail + levels;
  const double count = std::pow(std::pow(double(rules.d), rules.dimension), last) * double(rules.points.size());
  if (count > kMaxLevelPoints)
    throw ResourceLimit("voronoi: level " + std::to_string(last) + " would hold " + std::to_string(count) +
                        " points, more than the limit of 20000000; use a lower level" +
                        (levels > 0 ? " or fewer refinement levels" : ""));
  Refiner r{rules, levels, last, refine, keep_unwrapped, std::vector<double>(size_t(last) + 1, 1.0), {}};
  for (int i = 1; i <= last; ++i) r.scale[size_t(i)] = r.scale[size_t(i) - 1] / rules.d;  // powers of d: exact enough
  r.out.tiles_per_level.assign(size_t(levels) + 1, 0);
  r.out.level.dimension = rules.dimension;
  r.out.level.points.reserve(size_t(count));
  r.out.level.colours.reserve(size_t(count));
  r.out.level.shapes.reserve(size_t(count));
  if (keep_unwrapped) r.out.level.unwrapped.reserve(size_t(count));
  for (size_t c = 0; c < rules.points.size(); ++c) r.visit(0, int(c), int(c), rules.points[c], -1);
  r.out.level.colour_count = int(r.out.tile_level.size());
  return r.out;
}

}  // namespace

Level generate_level(const Rules& rules, int k, bool keep_unwrapped) {
  if (k < 0) throw InvalidInput("voronoi: the level must be >= 0, got " + std::to_string(k));
  return refined(rules, k, 0, nullptr, keep_unwrapped).level;
}

RefinedLevel refine_level(const Rules& rules, int detail, int levels,
                          const std::function<bool(const std::vector<double>& x, int l)>& refine, bool keep_unwrapped) {
  if (detail < 0 || levels < 0)
    throw InvalidInput("voronoi: a refined level needs detail >= 0 and levels >= 0, got " + std::to_string(detail) +
                       " and " + std::to_string(levels));
  return refined(rules, detail, levels, &refine, keep_unwrapped);
}

std::vector<double> cell_measures_2d(const Level& level) { return scan_cells(level, 2, false).measures; }

std::vector<double> cell_measures_3d(const Level& level) { return scan_cells(level, 3, false).measures; }

std::vector<Cell> periodic_cells(const Level& level) {
  if (level.dimension != 2 && level.dimension != 3)
    throw InvalidInput("voronoi: a level must be 2D or 3D, got " + std::to_string(level.dimension));
  const int n = level.dimension;
  check_level(level, n);
  const Grid grid = make_grid(level);
  std::vector<Cell> cells(level.points.size());
  CellWork w;
  for (size_t self = 0; self < level.points.size(); ++self) {
    build_cell(level, grid, self, w);
    Cell& cell = cells[self];
    cell.coincident = w.coincident;
    const auto& x = level.points[self];
    if (n == 2) {
      const size_t count = w.poly2.v.size();
      for (size_t i = 0; i < count; ++i) {
        const V2& p = w.poly2.v[i];
        const V2& q = w.poly2.v[(i + 1) % count];
        if (std::hypot(q[0] - p[0], q[1] - p[1]) <= 1e-15) continue;
        cell.faces.push_back({{p[0], p[1], 0.0}, {q[0], q[1], 0.0}});
        cell.across.push_back(w.neighbours[size_t(w.poly2.label[i])]);
      }
    } else {
      const V3 xs{x[0], x[1], x[2]};
      for (size_t i = 0; i < w.poly3.faces.size(); ++i) {
        std::vector<V3> face;
        for (const V3& p : w.poly3.faces[i])
          if (face.empty() || std::sqrt(dot3(sub3(p, face.back()), sub3(p, face.back()))) > 1e-15) face.push_back(p);
        while (face.size() > 1 && std::sqrt(dot3(sub3(face.front(), face.back()), sub3(face.front(), face.back()))) <= 1e-15)
          face.pop_back();
        if (face.size() < 3) continue;
        const V3 a = area_vector(face);
        if (std::sqrt(dot3(a, a)) <= 1e-24) continue;
        if (dot3(a, sub3(face[0], xs)) < 0) std::reverse(face.begin(), face.end());
        cell.faces.push_back(std::move(face));
        cell.across.push_back(w.neighbours[size_t(w.poly3.label[i])]);
      }
    }
  }
  return cells;
}

std::vector<std::pair<int, int>> colour_graph(const Level& level) {
  if (level.dimension != 2 && level.dimension != 3)
    throw InvalidInput("voronoi: a level must be 2D or 3D, got " + std::to_string(level.dimension));
  const CellScan scan = scan_cells(level, level.dimension, true);
  return {scan.graph.begin(), scan.graph.end()};
}

}  // namespace voronoi
}  // namespace lacuna
