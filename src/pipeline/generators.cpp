#include "pipeline/generators.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>

#include "cifs/nurbs.h"
#include "cifs/tessellate.h"
#include "curves/sweep.h"
#include "errors.h"
#include "recipe/cifs_system.h"

namespace lacuna {

CifsTessellation tessellate_system(cifs::Cifs system, int level) {
  cifs::complete_primitives(system.automaton);
  CifsTessellation t;
  t.pieces = cifs::count_pieces(system.automaton, level);
  if (t.pieces > kMaxListedPieces)
    throw ResourceLimit("level " + std::to_string(level) + " has " + std::to_string(t.pieces) +
                        " pieces; printing more than 20 000 000 is refused, use a recipe to build the solid");
  t.dimension = cifs::primitive_dimension(system.automaton.states[size_t(system.automaton.initial)].primitive);
  if (t.dimension == 1) {
    for (const auto& line : cifs::tessellate_curves(system, level)) {
      std::vector<uint32_t> ids;
      for (const Vec3d& p : line) {
        ids.push_back(uint32_t(t.points_mm.size()));
        t.points_mm.push_back(p);
      }
      t.cells.push_back(std::move(ids));
    }
  } else if (t.dimension == 2) {
    TriMesh mesh = cifs::tessellate_surface(system, level);
    t.points_mm = std::move(mesh.positions_mm);
    for (const auto& tri : mesh.triangles) t.cells.push_back({tri[0], tri[1], tri[2]});
  } else {
    cifs::for_each_piece(system, level, [&](const cifs::Piece& piece) {
      std::vector<uint32_t> ids;
      for (Eigen::Index i = 0; i < piece.vertices->cols(); ++i) {
        ids.push_back(uint32_t(t.points_mm.size()));
        t.points_mm.push_back(Vec3d{(*piece.vertices)(0, i), (*piece.vertices)(1, i), (*piece.vertices)(2, i)});
      }
      for (const auto& face : cifs::primitive_faces(system.automaton.states[size_t(piece.state)])) {
        std::vector<uint32_t> f;
        for (int k : face) f.push_back(ids[size_t(k)]);
        t.faces.push_back(std::move(f));
      }
      t.cells.push_back(std::move(ids));
    });
  }
  return t;
}

NurbsCurvePoints nurbs_curve_points(int degree, const std::vector<double>& knots, const nlohmann::json& control_points,
                                    int level, const std::string& file) {
  // Through the system reader, which checks the knots and the points.
  const nlohmann::json system = {{"nurbs_curve", {{"degree", degree}, {"knots", knots}}},
                                 {"control_points_mm", control_points}};
  const cifs::Cifs c = cifs::parse_system(system, file, "");
  if (level < 0 || level > 24) throw InvalidInput("level: expected 0 .. 24, got " + std::to_string(level));
  NurbsCurvePoints out;
  uint64_t i = 0;
  for (const auto& line : cifs::tessellate_curves(c, level))
    for (const Vec3d& p : line) {
      out.points_mm.push_back(p);
      out.parameters.push_back(cifs::nurbs_vertex_parameter(degree, knots, level, i++));
    }
  if (level > 16) return out;
  // Per state, its start tangent (the limit frame of its left half, into the piece) and end tangent
  // (of its right half, into the piece, so reversed); sub-pieces in address order, left first.
  cifs::Automaton a = c.automaton;
  cifs::complete_primitives(a);
  std::vector<std::optional<cifs::FixedPointFrame>> starts(a.states.size()), ends(a.states.size());
  auto frame = [&](std::vector<std::optional<cifs::FixedPointFrame>>& cache, int state, int symbol, int toward) {
    if (!cache[size_t(state)])
      cache[size_t(state)] = cifs::limit_frame(a, state, symbol, 1, a.states[size_t(state)].vertices.col(toward));
    return *cache[size_t(state)];
  };
  auto tangent = [&](const Eigen::MatrixXd& word, const cifs::FixedPointFrame& f, double sign) {
    if (!f.smooth) return Vec3d{0, 0, 0};
    const Eigen::VectorXd x = word * f.point, d = word * f.directions[0];
    const Eigen::VectorXd h = c.control_points * x, dh = c.control_points * d;
    Eigen::Vector3d v = c.rational ? Eigen::Vector3d(dh.head<3>() / h(3) - h.head<3>() * dh(3) / (h(3) * h(3)))
                                   : Eigen::Vector3d(dh.head<3>());
    v *= sign / v.norm();
    return Vec3d{v.x(), v.y(), v.z()};
  };
  std::function<void(int, const Eigen::MatrixXd&, int)> visit = [&](int state, const Eigen::MatrixXd& word, int depth) {
    if (depth == level) {
      out.tangents.push_back(tangent(word, frame(starts, state, 0, 1), 1));
      return;
    }
    for (int symbol : {0, 1}) {
      const cifs::Transition* t = cifs::find_transition(a, state, symbol);
      visit(t->target, word * t->matrix, depth + 1);
    }
  };
  const int k = a.states[size_t(a.initial)].control_points;
  visit(a.initial, Eigen::MatrixXd::Identity(k, k), 0);
  // The last point: the end of the last sub-piece.
  Eigen::MatrixXd word = Eigen::MatrixXd::Identity(k, k);
  int state = a.initial;
  for (int depth = 0; depth < level; ++depth) {
    const cifs::Transition* t = cifs::find_transition(a, state, 1);
    word = word * t->matrix;
    state = t->target;
  }
  out.tangents.push_back(tangent(word, frame(ends, state, 1, 0), -1));
  return out;
}

namespace {

// The drawn polylines, refusing more than 20 000 000 points in all.
struct Drawing {
  std::vector<DrawnCurve> drawn;
  uint64_t total = 0;
  void keep(int order, std::vector<Vec3d> points, bool closed) {
    total += points.size();
    if (total > 20'000'000) throw ResourceLimit("more than 20 000 000 points; ask for lower orders");
    drawn.push_back(DrawnCurve{order, closed, std::move(points)});
  }
};

void draw_on_map(Drawing& drawing, curves::CurveKind kind, const std::vector<int>& orders,
                 const curves::SurfaceMap& map, double tolerance) {
  curves::MapOptions options;
  options.tolerance_mm = tolerance;
  for (const curves::Curve2& c : curves::superposition(kind, orders)) {
    curves::Polyline3 line = curves::map_polyline(c.polyline, map, options);
    drawing.keep(c.order, std::move(line.points), line.closed);
  }
}

}  // namespace

std::vector<DrawnCurve> curve_points(curves::CurveKind kind, bool hilbert3d, const std::vector<int>& orders,
                                     CurveSurface surface, double tolerance) {
  Drawing drawing;
  if (hilbert3d) {
    if (surface != CurveSurface::kPlane && surface != CurveSurface::kCube)
      throw InvalidInput("a 3D Hilbert curve fills the cube; it takes no surface");
    for (const curves::Curve3& c : curves::superposition3d(orders))
      drawing.keep(c.order, c.polyline.points, c.polyline.closed);
    return std::move(drawing.drawn);
  }
  switch (surface) {
    case CurveSurface::kPlane:
      for (const curves::Curve2& c : curves::superposition(kind, orders)) {
        std::vector<Vec3d> points;
        for (const Vec2d& p : c.polyline.points) points.push_back(Vec3d{p.x, p.y, 0});
        drawing.keep(c.order, std::move(points), c.polyline.closed);
      }
      break;
    case CurveSurface::kCube: {
      curves::MapOptions options;
      options.tolerance_mm = tolerance;
      for (int order : orders)
        for (const curves::Polyline3& line : curves::cube_curve(kind, order, options))
          drawing.keep(order, line.points, line.closed);
      break;
    }
    case CurveSurface::kSphere: draw_on_map(drawing, kind, orders, curves::sphere_map(), tolerance); break;
    case CurveSurface::kCylinder: draw_on_map(drawing, kind, orders, curves::cylinder_map(), tolerance); break;
    case CurveSurface::kTorus: draw_on_map(drawing, kind, orders, curves::torus_map(), tolerance); break;
    case CurveSurface::kCone: draw_on_map(drawing, kind, orders, curves::cone_map(), tolerance); break;
  }
  return std::move(drawing.drawn);
}

std::vector<DrawnCurve> curve_points(curves::CurveKind kind, const std::vector<int>& orders,
                                     const curves::SurfaceMap& surface, double tolerance) {
  Drawing drawing;
  draw_on_map(drawing, kind, orders, surface, tolerance);
  return std::move(drawing.drawn);
}

CurveFillRate curve_fill_rate(curves::CurveKind kind, const std::vector<int>& orders, double width) {
  if (!(width > 0)) throw InvalidInput("expected a positive stroke width (the square has side 2)");
  const std::vector<curves::Curve2> set = curves::superposition(kind, orders);
  const std::vector<curves::Polyline2> lines = curves::polylines_of(set);
  CurveFillRate r;
  for (const curves::Curve2& c : set) r.orders.push_back(c.order);
  for (const curves::Polyline2& l : lines) {
    const size_t n = l.points.size();
    for (size_t i = 0; i + 1 < n + (l.closed ? 1 : 0); ++i) {
      const Vec2d d = l.points[(i + 1) % n] - l.points[i];
      r.length += std::hypot(d.x, d.y);
      ++r.segments;
    }
  }
  r.fill_rate = curves::fill_rate_exact(lines, width);
  r.fill_rate_simple = curves::fill_rate_estimate(lines, width);
  return r;
}

ExponentialFit exponential_fit(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size() || x.size() < 2) throw InvalidInput("an exponential fit needs two or more (x, y) points");
  double mx = 0, my = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    if (!(y[i] > 0) || !std::isfinite(y[i]) || !std::isfinite(x[i]))
      throw InvalidInput("an exponential fit needs finite x and positive y, got y = " + message_number(y[i]));
    mx += x[i];
    my += std::log(y[i]);
  }
  mx /= double(x.size());
  my /= double(x.size());
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (std::log(y[i]) - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  if (!(sxx > 0)) throw InvalidInput("an exponential fit needs distinct x");
  ExponentialFit f;
  f.b = sxy / sxx;
  f.a = std::exp(my - f.b * mx);
  return f;
}

FillRateSeries curve_fill_rate_series(curves::CurveKind kind, const std::vector<int>& orders, double width) {
  std::vector<int> sorted = orders;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  if (sorted.size() < 2) throw InvalidInput("a fill-rate series needs two or more orders");
  FillRateSeries s;
  std::vector<double> n, exact, simple;
  for (size_t k = 1; k <= sorted.size(); ++k) {
    s.rates.push_back(curve_fill_rate(kind, std::vector<int>(sorted.begin(), sorted.begin() + long(k)), width));
    n.push_back(sorted[k - 1]);
    exact.push_back(100 * s.rates.back().fill_rate);
    simple.push_back(100 * s.rates.back().fill_rate_simple);
  }
  s.exact_fit = exponential_fit(n, exact);
  s.simple_fit = exponential_fit(n, simple);
  return s;
}

namespace {

// The footprint of tubes of diameter `width` along the drawn curves on the surface the maps make up
// (the cube: one per face), integrated over samples x samples cells of each map's square.
SurfaceFillRate surface_fill_rate(const std::vector<DrawnCurve>& drawn, const std::vector<curves::SurfaceMap>& maps,
                                  double width, int samples) {
  const int n = samples ? samples : int(std::clamp(std::ceil(16 / width), 256.0, 20000.0));
  SurfaceFillRate r;
  r.samples = n;
  std::vector<curves::Polyline3> lines;
  for (const DrawnCurve& c : drawn) {
    if (r.orders.empty() || r.orders.back() != c.order) r.orders.push_back(c.order);
    for (size_t i = 0; i + 1 < c.points.size() + (c.closed ? 1 : 0); ++i)
      r.length += norm(c.points[(i + 1) % c.points.size()] - c.points[i]);
    lines.push_back(curves::Polyline3{c.points, c.closed});
  }
  const curves::TubeFootprint footprint(lines, width / 2);
  for (const curves::SurfaceMap& map : maps) {
    std::vector<curves::SurfaceCoverage> rows(static_cast<size_t>(n));
    tbb::parallel_for(0, n, [&](int j) { rows[size_t(j)] = curves::surface_coverage(map, footprint, n, j, j + 1); });
    for (const curves::SurfaceCoverage& row : rows) r.area += row.area, r.covered_area += row.covered_area;
  }
  r.fill_rate = r.area > 0 ? r.covered_area / r.area : 0;
  r.fill_rate_simple = r.area > 0 ? r.length * width / r.area : 0;
  return r;
}

void check_fill_rate_options(double width, int samples) {
  if (!(width > 0) || !std::isfinite(width)) throw InvalidInput("expected a positive tube width");
  if (samples != 0 && (samples < 16 || samples > 20000))
    throw InvalidInput("samples: expected 16 .. 20000 per side, or 0 for eight cells across a tube");
}

}  // namespace

SurfaceFillRate curve_surface_fill_rate(curves::CurveKind kind, const std::vector<int>& orders, double width,
                                        CurveSurface surface, int samples, double tolerance) {
  check_fill_rate_options(width, samples);
  std::vector<curves::SurfaceMap> maps;
  switch (surface) {
    case CurveSurface::kPlane: maps.push_back(curves::plane_map()); break;
    case CurveSurface::kSphere: maps.push_back(curves::sphere_map()); break;
    case CurveSurface::kCylinder: maps.push_back(curves::cylinder_map()); break;
    case CurveSurface::kTorus: maps.push_back(curves::torus_map()); break;
    case CurveSurface::kCone: maps.push_back(curves::cone_map()); break;
    case CurveSurface::kCube:
      for (int face = 0; face < 6; ++face) maps.push_back(curves::cube_face_map(face));
      break;
  }
  return surface_fill_rate(curve_points(kind, false, orders, surface, tolerance), maps, width, samples);
}

SurfaceFillRate curve_surface_fill_rate(curves::CurveKind kind, const std::vector<int>& orders, double width,
                                        const curves::SurfaceMap& surface, int samples, double tolerance) {
  check_fill_rate_options(width, samples);
  return surface_fill_rate(curve_points(kind, orders, surface, tolerance), {surface}, width, samples);
}

VoronoiCells voronoi_cells(const voronoi::Rules& rules, int level, bool scaled_children) {
  if (level < 0 || level > 12) throw InvalidInput("level: expected 0 .. 12, got " + std::to_string(level));
  VoronoiCells c;
  c.level = voronoi::generate_level(rules, level);
  c.measures = rules.dimension == 2 ? voronoi::cell_measures_2d(c.level) : voronoi::cell_measures_3d(c.level);
  // Shifted children make no lattice to reuse cells on.
  if (scaled_children) c.walls = voronoi::extract_walls(rules, c.level);
  return c;
}

PlateMeasures measure_plate(const bcifs::Plate& plate, int first, int last) {
  if (first < 0 || last < first || last > kMaxTopologyLevel || first > kMaxGeometryLevel)
    throw InvalidInput("levels: expected 0 <= first <= last <= " + std::to_string(kMaxTopologyLevel) + " and first <= " +
                       std::to_string(kMaxGeometryLevel) + ", got " + std::to_string(first) + ".." + std::to_string(last));
  const bcifs::PlateOptions& spec = plate.options;
  PlateMeasures m;
  for (size_t f = 0; f < spec.assembly.faces.size(); ++f) {
    m.face_types.push_back(plate.rules.roots[f]);
    m.faces.push_back(bcifs::lacunarity(plate.rules, plate.rules.roots[f], last));
  }
  std::vector<bcifs::Leaf> faces_at_level_0;
  for (auto& face : bcifs::realize_assembly(plate.rules, spec.assembly, spec.controls, 0, spec.options, spec.bends))
    faces_at_level_0.insert(faces_at_level_0.end(), face.begin(), face.end());
  // The realization to level 8 at most; the counts (no geometry) to `last`.
  m.geometry = bcifs::geometric_measures(plate.rules, faces_at_level_0, first, std::min(last, kMaxGeometryLevel),
                                         spec.options, &m.polygons);
  m.region = bcifs::box_count_region(m.polygons);
  m.boundary = bcifs::box_count_segments(bcifs::boundary_segments(m.polygons));
  return m;
}

VolumeCellMeasures measure_volume(const bcifs::VolumeSpec& spec, const bcifs::VolumeGeometryOptions& options, int last) {
  if (last < 0 || last > kMaxTopologyLevel)
    throw InvalidInput("levels: expected a last level from 0 to " + std::to_string(kMaxTopologyLevel) + ", got " +
                       std::to_string(last));
  const bcifs::VolumeRules rules = bcifs::build_volume_rules(spec);
  VolumeCellMeasures m;
  m.cell_types = rules.roots;
  for (int root : rules.roots) m.cells.push_back(bcifs::volume_lacunarity(rules, root, last));
  m.cell_type_count = rules.cells.size();
  m.face_type_count = rules.faces.rules.size();
  while (m.geometry_last < last && bcifs::volume_cells(rules, m.geometry_last + 1) <= kMaxMeasuredCells)
    ++m.geometry_last;
  bcifs::VolumeLevel deepest;
  m.geometry = bcifs::volume_measures(rules, spec, m.geometry_last, options, &deepest);
  const std::vector<ConvexCells> pieces = bcifs::convex_pieces(deepest, spec);
  const bcifs::VoxelGrid grid = bcifs::voxel_grid(pieces, kVolumeBoxGrid);
  const size_t n = size_t(grid.size);
  std::vector<uint8_t> mask(n * n * n);
  tbb::parallel_for(tbb::blocked_range<int>(0, grid.size, 8), [&](const tbb::blocked_range<int>& r) {
    bcifs::mark_voxels(pieces, grid, r.begin(), r.end(), mask.data() + size_t(r.begin()) * n * n);
  });
  size_t set = 0;
  for (uint8_t v : mask) set += v;
  m.grid_fill = double(set) / double(mask.size());
  m.region = bcifs::box_count_3d(mask, grid.size, false);
  m.boundary = bcifs::box_count_3d(mask, grid.size, true);
  Vec3d lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const ConvexCells& cells : pieces)
    for (const Vec3d& p : cells.corners_mm)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
  tbb::parallel_for(0, 3, [&](int axis) {
    m.section_mm[size_t(axis)] = 0.5 * (lo[axis] + hi[axis]);
    m.sections[size_t(axis)] = bcifs::section_mask(pieces, grid, axis, m.section_mm[size_t(axis)], kSectionPixels);
  });
  return m;
}

}  // namespace lacuna
