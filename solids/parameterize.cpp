#include "solids/parameterize.h"

#include <CGAL/Eigen_matrix.h>
#include <CGAL/Eigen_vector.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/Error_code.h>
#include <CGAL/Surface_mesh_parameterization/Mean_value_coordinates_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Square_border_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>
#include <Eigen/SparseLU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "errors.h"
#include "solids/mesh_topology.h"

namespace lacuna {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point2 = Kernel::Point_2;
using Point3 = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point3>;
using VertexIndex = SurfaceMesh::Vertex_index;
namespace smp = CGAL::Surface_mesh_parameterization;
using SquareBorder = smp::Square_border_arc_length_parameterizer_3<SurfaceMesh>;
// A direct solver for CGAL's fixed-border parameterizers (a model of SparseLinearAlgebraTraits_d): the
// mean-value system is not symmetric, and the default iterative BiCGSTAB can stop short of convergence
// on large patches. The parameterizer solves the same matrix for u and then for v: it is factored once.
class FactorOnceSolver {
 public:
  using NT = double;
  using Matrix = CGAL::Eigen_sparse_matrix<double>;
  using Vector = CGAL::Eigen_vector<double>;

  bool linear_solver(const Matrix& A, const Vector& B, Vector& X, NT& D) {
    D = 1;
    if (state_->factored != &A) {
      state_->lu.analyzePattern(A.eigen_object());
      state_->lu.factorize(A.eigen_object());
      state_->factored = &A;
    }
    if (state_->lu.info() != Eigen::Success) return false;
    X = state_->lu.solve(B);
    return state_->lu.info() == Eigen::Success;
  }

 private:
  struct State {
    Eigen::SparseLU<Matrix::EigenType, Eigen::COLAMDOrdering<int>> lu;
    const Matrix* factored = nullptr;  // the matrix lu holds the factors of
  };
  std::shared_ptr<State> state_ = std::make_shared<State>();
};
using MeanValueParameterizer = smp::Mean_value_coordinates_parameterizer_3<SurfaceMesh, SquareBorder, FactorOnceSolver>;

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr double kPi = 3.14159265358979323846;

std::string describe(const Vec3d& p) {
  std::ostringstream s;
  s << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return s.str();
}

// The patch with its used vertices renumbered 0 .. V-1 in their original order, and its boundary.
struct Patch {
  std::vector<uint32_t> original;  // original index of each used vertex
  std::vector<Vec3d> positions;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<uint32_t> boundary;  // the boundary loop in the direction of its triangles' edges
};

// Checks that the mesh is a disk-like patch (throws InvalidInput naming the first problem found) and
// returns it compacted, with its boundary loop.
Patch disk_patch(const TriMesh& mesh) {
  const size_t nt = mesh.triangles.size();
  if (nt == 0) throw InvalidInput("the patch has no triangles");
  if (nt > (size_t(1) << 30)) throw InvalidInput("the patch has too many triangles (more than 2^30)");
  const size_t nv_in = mesh.positions_mm.size();

  Patch patch;
  std::vector<uint32_t> index(nv_in, kNone);
  for (size_t t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int c = 0; c < 3; ++c) {
      if (tri[c] >= nv_in) {
        throw InvalidInput("triangle " + std::to_string(t) + " names vertex " + std::to_string(tri[c]) +
                           ", but the patch has " + std::to_string(nv_in) + " vertices");
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) {
      throw InvalidInput("triangle " + std::to_string(t) + " repeats a vertex (" + std::to_string(tri[0]) + ", " +
                         std::to_string(tri[1]) + ", " + std::to_string(tri[2]) + ")");
    }
    for (int c = 0; c < 3; ++c) index[tri[c]] = 0;
  }
  for (size_t v = 0; v < nv_in; ++v) {
    if (index[v] == kNone) continue;
    if (!is_finite(mesh.positions_mm[v])) {
      throw InvalidInput("vertex " + std::to_string(v) + " of the patch has a non-finite position");
    }
    index[v] = uint32_t(patch.original.size());
    patch.original.push_back(uint32_t(v));
    patch.positions.push_back(mesh.positions_mm[v]);
  }
  const size_t nv = patch.positions.size();
  patch.triangles.reserve(nt);
  for (size_t t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    patch.triangles.push_back({index[tri[0]], index[tri[1]], index[tri[2]]});
    const Vec3d& a = mesh.positions_mm[tri[0]];
    const Vec3d& b = mesh.positions_mm[tri[1]];
    const Vec3d& c = mesh.positions_mm[tri[2]];
    double longest = std::max({norm(b - a), norm(c - b), norm(a - c)});
    // Mean-value weights divide by edge lengths and by sines of angles: a triangle this thin has none.
    if (!(norm(cross(b - a, c - a)) > 1e-12 * longest * longest)) {
      throw InvalidInput("triangle " + std::to_string(t) + " is degenerate: its corners " + describe(a) + ", " +
                         describe(b) + ", " + describe(c) + " are collinear or coincide");
    }
  }

  TriMesh indexed;
  indexed.positions_mm = patch.positions;
  indexed.triangles = patch.triangles;
  const VertexComponents pieces = vertex_components(indexed);
  if (pieces.count != 1) {
    throw InvalidInput("the patch has " + std::to_string(pieces.count) +
                       " separate pieces (connected components); a disk-like patch is one piece");
  }

  const VertexCorners corners = vertex_corners(indexed);
  const EdgeTopology edges = edge_topology(indexed, corners);
  auto from = [&](uint32_t h) { return half_edge_from(indexed, h); };
  auto to = [&](uint32_t h) { return half_edge_to(indexed, h); };
  auto vertex_name = [&](uint32_t v) { return std::to_string(patch.original[v]) + " " + describe(patch.positions[v]); };
  if (!edges.non_manifold.empty()) {
    const uint32_t h = edges.non_manifold.front(), a = from(h), b = to(h);
    size_t faces = 0;
    for (const auto& tri : patch.triangles) {
      const bool has_a = tri[0] == a || tri[1] == a || tri[2] == a, has_b = tri[0] == b || tri[1] == b || tri[2] == b;
      faces += has_a && has_b;
    }
    throw InvalidInput("not manifold at edge between vertices " + vertex_name(a) + " and " + vertex_name(b) + ": " +
                       std::to_string(faces) + " triangles share it");
  }
  if (!edges.misoriented.empty()) {
    const uint32_t h = edges.misoriented.front();
    throw InvalidInput("inconsistently oriented at edge between vertices " + vertex_name(from(h)) + " and " +
                       vertex_name(to(h)) + ": both its triangles run it the same way");
  }
  std::vector<uint32_t> boundary_out(nv, 0);
  for (uint32_t h : edges.boundary) {
    if (boundary_out[from(h)]++) {
      throw InvalidInput("not manifold at vertex " + vertex_name(from(h)) +
                         ": the boundary passes through it more than once");
    }
  }
  const std::vector<uint32_t> fans = vertex_fans(indexed, edges, corners);
  for (uint32_t v = 0; v < nv; ++v) {
    if (fans[v] > 1) {
      throw InvalidInput("not manifold at vertex " + vertex_name(v) + ": its triangles form " +
                         std::to_string(fans[v]) + " fans that touch only there");
    }
  }
  if (edges.boundary_edges == 0) throw InvalidInput("the patch is closed: it has no boundary to flatten");

  const std::vector<std::vector<uint32_t>> loops = boundary_loops(indexed, edges);
  if (loops.size() != 1) {
    throw InvalidInput("the patch has " + std::to_string(loops.size()) + " boundary loops; a disk-like patch has one (" +
                       std::to_string(loops.size() - 1) + " holes would have to be cut open or filled)");
  }
  patch.boundary = loops.front();
  const int64_t euler = euler_characteristics(indexed, edges, pieces).front();
  if (euler != 1) {
    throw InvalidInput("the patch has Euler characteristic " + std::to_string(euler) +
                       " (vertices - edges + triangles), a disk-like patch has 1: it has " +
                       std::to_string((1 - euler) / 2) + " handles; cut them open first");
  }
  if (patch.boundary.size() < 4) {
    throw InvalidInput("the patch's boundary has " + std::to_string(patch.boundary.size()) +
                       " edges; at least 4 are needed to put the square's corners on boundary vertices");
  }
  return patch;
}

// Positions along the boundary (indices into patch.boundary) of the square's four corners, in the
// boundary's direction; see flatten_patch() for the rule.
std::array<size_t, 4> choose_corners(const Patch& patch) {
  const std::vector<uint32_t>& loop = patch.boundary;
  const size_t n = loop.size();
  // Arc length along two turns of the loop, so that a span from any start is a difference.
  std::vector<double> arc(2 * n + 1, 0.0);
  for (size_t j = 0; j < 2 * n; ++j) {
    arc[j + 1] = arc[j] + norm(patch.positions[loop[(j + 1) % n]] - patch.positions[loop[j % n]]);
  }
  const double length = arc[n];

  std::vector<size_t> position(patch.positions.size(), n);
  for (size_t i = 0; i < n; ++i) position[loop[i]] = i;
  std::vector<double> angle_sum(n, 0.0);
  std::vector<std::array<size_t, 3>> on_boundary;  // triangles with all three corners on the boundary
  for (const auto& tri : patch.triangles) {
    for (int c = 0; c < 3; ++c) {
      size_t i = position[tri[c]];
      if (i == n) continue;
      Vec3d e1 = patch.positions[tri[(c + 1) % 3]] - patch.positions[tri[c]];
      Vec3d e2 = patch.positions[tri[(c + 2) % 3]] - patch.positions[tri[c]];
      angle_sum[i] += std::atan2(norm(cross(e1, e2)), dot(e1, e2));
    }
    if (position[tri[0]] < n && position[tri[1]] < n && position[tri[2]] < n) {
      on_boundary.push_back({position[tri[0]], position[tri[1]], position[tri[2]]});
    }
  }

  // Corner offsets (steps from the start) for a start: each the one closest to k quarters of the length,
  // after the previous one and leaving room for the rest.
  auto offsets_from = [&](size_t start) {
    std::array<size_t, 5> r{0, 0, 0, 0, n};
    for (size_t k = 1; k < 4; ++k) {
      size_t lo = r[k - 1] + 1, hi = n - (4 - k);
      double target = arc[start] + double(k) * length / 4;
      size_t j = size_t(std::lower_bound(arc.begin() + long(start + lo), arc.begin() + long(start + hi + 1), target) -
                        arc.begin()) - start;
      if (j > hi) {
        j = hi;
      } else if (j > lo && std::fabs(arc[start + j - 1] - target) <= std::fabs(arc[start + j] - target)) {
        --j;
      }
      r[k] = j;
    }
    return r;
  };

  std::vector<size_t> candidates(n);
  std::iota(candidates.begin(), candidates.end(), size_t(0));
  // Each candidate costs a pass over the boundary triangles: on long boundaries only the sharpest try.
  constexpr size_t kMaxCandidates = 256;
  if (n > kMaxCandidates) {
    // Angles equal up to rounding (a smooth boundary) rank by vertex index.
    auto key = [&](size_t i) { return std::make_pair(std::llround(angle_sum[i] * 1e9), loop[i]); };
    std::sort(candidates.begin(), candidates.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
    candidates.resize(kMaxCandidates);
  }
  std::sort(candidates.begin(), candidates.end(), [&](size_t a, size_t b) { return loop[a] < loop[b]; });

  size_t best_start = candidates[0];
  std::array<size_t, 5> best_offsets{};
  size_t best_flat = std::numeric_limits<size_t>::max();
  double best_turning = -HUGE_VAL;
  for (size_t start : candidates) {
    std::array<size_t, 5> r = offsets_from(start);
    size_t flat = 0;
    for (const auto& tri : on_boundary) {
      for (size_t k = 0; k < 4; ++k) {
        bool on_side = true;
        for (size_t i : tri) {
          size_t step = (i + n - start) % n;
          on_side = on_side && ((r[k] <= step && step <= r[k + 1]) || (k == 3 && step == 0));
        }
        if (on_side) {
          ++flat;
          break;
        }
      }
    }
    double turning = 0;
    for (size_t k = 0; k < 4; ++k) turning += kPi - angle_sum[(start + r[k]) % n];
    if (flat < best_flat || (flat == best_flat && turning > best_turning + 1e-9)) {
      best_start = start;
      best_offsets = r;
      best_flat = flat;
      best_turning = turning;
    }
  }
  std::array<size_t, 4> corners;
  for (size_t k = 0; k < 4; ++k) corners[k] = (best_start + best_offsets[k]) % n;
  return corners;
}

double signed_area(const Vec2d& a, const Vec2d& b, const Vec2d& c) {
  return 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

// The square coordinates of the compacted patch's vertices.
std::vector<Vec2d> flatten(const Patch& patch) {
  const size_t nv = patch.positions.size();
  SurfaceMesh mesh;
  mesh.reserve(nv, 3 * patch.triangles.size() / 2 + patch.boundary.size(), patch.triangles.size());
  for (const Vec3d& p : patch.positions) mesh.add_vertex(Point3(p.x, p.y, p.z));
  for (const auto& tri : patch.triangles) {
    if (mesh.add_face(VertexIndex(tri[0]), VertexIndex(tri[1]), VertexIndex(tri[2])) == SurfaceMesh::null_face()) {
      throw std::logic_error("flatten_patch: CGAL's Surface_mesh rejected a triangle of a checked patch");
    }
  }

  std::array<size_t, 4> corners = choose_corners(patch);
  const size_t n = patch.boundary.size();
  auto corner = [&](size_t k) { return VertexIndex(patch.boundary[corners[k]]); };
  // CGAL walks the border the other way round (its border halfedges oppose the triangles' edges), from
  // the halfedge whose source is the first corner.
  SurfaceMesh::Halfedge_index start = mesh.halfedge(corner(0), VertexIndex(patch.boundary[(corners[0] + n - 1) % n]));
  if (start == SurfaceMesh::null_halfedge() || !mesh.is_border(start)) {
    throw std::logic_error("flatten_patch: the first corner's border halfedge is missing");
  }
  MeanValueParameterizer parameterizer(SquareBorder(corner(0), corner(1), corner(2), corner(3)));
  auto uv = mesh.add_property_map<VertexIndex, Point2>("v:uv", Point2(0, 0)).first;
  smp::Error_code status = smp::parameterize(mesh, parameterizer, start, uv);
  if (status != smp::OK) {
    throw InvalidInput(std::string("flattening the patch onto the square failed: ") + smp::get_error_message(status));
  }

  std::vector<Vec2d> xy(nv);
  for (size_t v = 0; v < nv; ++v) {
    const Point2& p = uv[VertexIndex(uint32_t(v))];
    xy[v] = {2 * p.x() - 1, 2 * p.y() - 1};
  }
  // Keep the orientation: the border, and with it the whole patch, came out either way round (the total
  // signed area is +-4 whatever the fold-overs). Swapping X and Y mirrors the square onto itself.
  double total = 0;
  for (const auto& tri : patch.triangles) total += signed_area(xy[tri[0]], xy[tri[1]], xy[tri[2]]);
  if (total < 0) {
    for (Vec2d& p : xy) std::swap(p.x, p.y);
  }
  size_t bad = 0, first_bad = 0;
  for (size_t t = 0; t < patch.triangles.size(); ++t) {
    const auto& tri = patch.triangles[t];
    if (!(signed_area(xy[tri[0]], xy[tri[1]], xy[tri[2]]) > 0)) {
      if (bad++ == 0) first_bad = t;
    }
  }
  if (bad > 0) {
    const auto& tri = patch.triangles[first_bad];
    throw InvalidInput("flattening the patch onto the square folds over or flattens " + std::to_string(bad) +
                       " triangles (first: triangle " + std::to_string(first_bad) + ", vertices " +
                       std::to_string(patch.original[tri[0]]) + ", " + std::to_string(patch.original[tri[1]]) + ", " +
                       std::to_string(patch.original[tri[2]]) +
                       "); a triangle whose corners all lie on the boundary between two of the square's corners "
                       "flattens to a segment: split it, or refine the patch near its boundary");
  }
  return xy;
}

// The flattened patch and a grid of buckets over the square, each listing (in increasing order) the
// triangles whose flattened bounding box meets it.
struct PatchChart {
  std::vector<Vec3d> positions;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<Vec2d> xy;
  std::vector<Vec3d> normals;  // unit, per triangle
  int grid = 1;                // buckets per side
  std::vector<uint32_t> bucket_start;  // grid * grid + 1
  std::vector<uint32_t> bucket_triangles;

  int cell(double x) const { return std::min(grid - 1, int(std::floor((x + 1) * 0.5 * grid))); }

  struct Location {
    uint32_t triangle;
    std::array<double, 3> weights;  // barycentric, non-negative, summing to 1
  };

  // The triangle containing (x, y) of the square (clamped onto it), or else the nearest one.
  Location locate(double x, double y) const {
    x = std::clamp(x, -1.0, 1.0);
    y = std::clamp(y, -1.0, 1.0);
    const Vec2d p{x, y};
    size_t b = size_t(cell(y)) * size_t(grid) + size_t(cell(x));
    uint32_t best = kNone;
    double best_min = -HUGE_VAL;
    std::array<double, 3> best_sub{};
    for (uint32_t i = bucket_start[b]; i < bucket_start[b + 1]; ++i) {
      uint32_t t = bucket_triangles[i];
      const auto& tri = triangles[t];
      const Vec2d &a = xy[tri[0]], &bb = xy[tri[1]], &c = xy[tri[2]];
      // Sub-areas opposite each corner, each computed from p so that p on a corner gives exact weights.
      std::array<double, 3> sub{signed_area(p, bb, c), signed_area(a, p, c), signed_area(a, bb, p)};
      double area = signed_area(a, bb, c);
      double lowest = std::min({sub[0], sub[1], sub[2]}) / area;
      if (lowest > best_min) {
        best_min = lowest;
        best = t;
        best_sub = sub;
      }
    }
    // Inside up to rounding: the usual case, points on edges and vertices included.
    if (best != kNone && best_min >= -1e-9) return {best, normalized(best_sub)};
    // Outside every triangle of the bucket by more than rounding (cannot happen for a tiling of the
    // square, kept for safety): the nearest triangle's nearest point.
    double best_distance = HUGE_VAL;
    Vec2d best_point = p;
    for (uint32_t i = bucket_start[b]; i < bucket_start[b + 1]; ++i) {
      uint32_t t = bucket_triangles[i];
      const auto& tri = triangles[t];
      for (int e = 0; e < 3; ++e) {
        Vec2d q = nearest_on_segment(p, xy[tri[e]], xy[tri[(e + 1) % 3]]);
        double d = std::hypot(q.x - p.x, q.y - p.y);
        if (d < best_distance) {
          best_distance = d;
          best = t;
          best_point = q;
        }
      }
    }
    const auto& tri = triangles[best];
    const Vec2d &a = xy[tri[0]], &bb = xy[tri[1]], &c = xy[tri[2]];
    return {best, normalized({signed_area(best_point, bb, c), signed_area(a, best_point, c),
                              signed_area(a, bb, best_point)})};
  }

  static std::array<double, 3> normalized(std::array<double, 3> w) {
    for (double& x : w) x = std::max(x, 0.0);
    double sum = w[0] + w[1] + w[2];
    if (!(sum > 0)) return {1.0 / 3, 1.0 / 3, 1.0 / 3};
    return {w[0] / sum, w[1] / sum, w[2] / sum};
  }

  static Vec2d nearest_on_segment(const Vec2d& p, const Vec2d& a, const Vec2d& b) {
    Vec2d d = b - a;
    double len2 = d.x * d.x + d.y * d.y;
    double s = len2 > 0 ? std::clamp(((p.x - a.x) * d.x + (p.y - a.y) * d.y) / len2, 0.0, 1.0) : 0.0;
    return a + d * s;
  }

  Vec3d point(double x, double y) const {
    if (std::isnan(x) || std::isnan(y)) return {NAN, NAN, NAN};
    Location at = locate(x, y);
    const auto& tri = triangles[at.triangle];
    return positions[tri[0]] * at.weights[0] + positions[tri[1]] * at.weights[1] + positions[tri[2]] * at.weights[2];
  }

  Vec3d normal(double x, double y) const {
    if (std::isnan(x) || std::isnan(y)) return {NAN, NAN, NAN};
    return normals[locate(x, y).triangle];
  }
};

std::shared_ptr<const PatchChart> chart_of(Patch patch, std::vector<Vec2d> xy) {
  auto chart = std::make_shared<PatchChart>();
  const size_t nt = patch.triangles.size();
  chart->normals.resize(nt);
  for (size_t t = 0; t < nt; ++t) {
    const auto& tri = patch.triangles[t];
    Vec3d n = cross(patch.positions[tri[1]] - patch.positions[tri[0]], patch.positions[tri[2]] - patch.positions[tri[0]]);
    chart->normals[t] = n / norm(n);
  }
  // About one bucket per triangle: flattened triangles tile the square, so a bucket meets a few.
  chart->grid = int(std::clamp(std::ceil(std::sqrt(double(nt))), 1.0, 2048.0));
  const int g = chart->grid;
  std::vector<std::array<int, 4>> ranges(nt);  // x0, x1, y0, y1 bucket ranges
  chart->bucket_start.assign(size_t(g) * size_t(g) + 1, 0);
  for (size_t t = 0; t < nt; ++t) {
    const auto& tri = patch.triangles[t];
    double x0 = std::min({xy[tri[0]].x, xy[tri[1]].x, xy[tri[2]].x});
    double x1 = std::max({xy[tri[0]].x, xy[tri[1]].x, xy[tri[2]].x});
    double y0 = std::min({xy[tri[0]].y, xy[tri[1]].y, xy[tri[2]].y});
    double y1 = std::max({xy[tri[0]].y, xy[tri[1]].y, xy[tri[2]].y});
    // The same cell() as the queries: a point inside a triangle's box lands in a bucket that lists it.
    ranges[t] = {chart->cell(std::max(x0, -1.0)), chart->cell(std::min(x1, 1.0)), chart->cell(std::max(y0, -1.0)),
                 chart->cell(std::min(y1, 1.0))};
    for (int j = ranges[t][2]; j <= ranges[t][3]; ++j) {
      for (int i = ranges[t][0]; i <= ranges[t][1]; ++i) ++chart->bucket_start[size_t(j) * size_t(g) + size_t(i) + 1];
    }
  }
  std::partial_sum(chart->bucket_start.begin(), chart->bucket_start.end(), chart->bucket_start.begin());
  chart->bucket_triangles.resize(chart->bucket_start.back());
  std::vector<uint32_t> fill(chart->bucket_start.begin(), chart->bucket_start.end() - 1);
  for (size_t t = 0; t < nt; ++t) {
    for (int j = ranges[t][2]; j <= ranges[t][3]; ++j) {
      for (int i = ranges[t][0]; i <= ranges[t][1]; ++i) {
        chart->bucket_triangles[fill[size_t(j) * size_t(g) + size_t(i)]++] = uint32_t(t);
      }
    }
  }
  chart->positions = std::move(patch.positions);
  chart->triangles = std::move(patch.triangles);
  chart->xy = std::move(xy);
  return chart;
}

}  // namespace

std::vector<Vec2d> flatten_patch(const TriMesh& patch) {
  Patch checked = disk_patch(patch);
  std::vector<Vec2d> xy = flatten(checked);
  std::vector<Vec2d> result(patch.positions_mm.size(), Vec2d{NAN, NAN});
  for (size_t v = 0; v < xy.size(); ++v) result[checked.original[v]] = xy[v];
  return result;
}

curves::SurfaceMap mesh_patch_map(const TriMesh& patch, const std::string& name) {
  Patch checked = disk_patch(patch);
  std::vector<Vec2d> xy = flatten(checked);
  std::shared_ptr<const PatchChart> chart = chart_of(std::move(checked), std::move(xy));
  curves::SurfaceMap map;
  map.name = name;
  map.point = [chart](double x, double y) { return chart->point(x, y); };
  map.normal = [chart](double x, double y) { return chart->normal(x, y); };
  return map;
}

}  // namespace lacuna
