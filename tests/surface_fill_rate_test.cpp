// Fill rates on surfaces the caller gives (a B-spline patch, a mesh patch): on flat patches that map
// the square onto a square with a distorted parameterization, the tubes' footprint integrated in
// parameter space equals the exact planar union of round-ended strokes along the drawn (distorted)
// curves, and the area that of the square.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "curves/curves.h"
#include "errors.h"
#include "pipeline/generators.h"
#include "solids/parameterize.h"
#include "mesh_fixtures.h"

namespace lacuna {
namespace {

using curves::CurveKind;

// The union of round-ended strokes of radius r along the polylines (z ignored), clipped to the box
// (lo, hi): a rectangle per segment and a 128-gon per point, unioned exactly.
double round_strokes_area(const std::vector<DrawnCurve>& drawn, double r, const Vec2d& lo, const Vec2d& hi) {
  std::vector<std::vector<Vec2d>> polygons;
  for (const DrawnCurve& c : drawn) {
    const size_t n = c.points.size();
    auto at = [&](size_t i) { return Vec2d{c.points[i % n].x, c.points[i % n].y}; };
    for (size_t i = 0; i < n; ++i) {
      std::vector<Vec2d> disk;
      for (int k = 0; k < 128; ++k) disk.push_back(at(i) + Vec2d{r * std::cos(2 * M_PI * k / 128), r * std::sin(2 * M_PI * k / 128)});
      polygons.push_back(disk);
      if (i + 1 == n && !c.closed) break;
      const Vec2d a = at(i), b = at(i + 1), t = (b - a) * (1 / std::hypot(b.x - a.x, b.y - a.y));
      const Vec2d side{-t.y * r, t.x * r};
      polygons.push_back({a - side, b - side, b + side, a + side});
    }
  }
  return curves::convex_union_area(polygons, lo, hi);
}

// The largest distance between a point of the square's curves and where the map puts it.
double largest_move(const curves::SurfaceMap& map, CurveKind kind, const std::vector<int>& orders) {
  double most = 0;
  for (const DrawnCurve& c : curve_points(kind, false, orders, CurveSurface::kPlane, 0.01))
    for (const Vec3d& p : c.points) most = std::max(most, norm(map.point(p.x, p.y) - p));
  return most;
}

// A degree-2 patch over [-1, 1]^2 with its border control points on the square's sides (so the
// image is the square) and the four inner ones pulled off their identity places.
curves::BSplinePatch distorted_square() {
  curves::BSplinePatch patch;
  patch.degree_u = patch.degree_v = 2;
  patch.count_u = patch.count_v = 4;
  const double at[4] = {-1, -0.5, 0.5, 1};  // the Greville abscissae: these places give the identity
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      Vec3d p{at[i], at[j], 0};
      if (i == 1 || i == 2) p.x += (j == 1 || j == 2) ? 0.3 : 0.0;
      if (j == 1 || j == 2) p.y += (i == 1 || i == 2) ? -0.2 : 0.0;
      patch.control_points.push_back(p);
    }
  return patch;
}

TEST(SurfaceFillRate, OnAFlatBSplinePatchItIsThePlanarUnionOfTheDrawnCurves) {
  const curves::SurfaceMap map = curves::bspline_map(distorted_square());
  const double width = 0.06, r = width / 2;
  for (const auto& [kind, orders] : {std::pair{CurveKind::kHilbert, std::vector<int>{3}},
                                     std::pair{CurveKind::kSierpinski, std::vector<int>{1, 2}}}) {
    const SurfaceFillRate rate = curve_surface_fill_rate(kind, orders, width, map, 2000, 1e-5);
    const std::vector<DrawnCurve> drawn = curve_points(kind, orders, map, 1e-5);
    const double planar = round_strokes_area(drawn, r, {-1, -1}, {1, 1}) / 4;
    EXPECT_NEAR(rate.area, 4, 1e-4);
    EXPECT_NEAR(rate.fill_rate, planar, 0.0005 * planar);
    EXPECT_GT(planar, 0.05);
    // Not the identity: the drawn curves moved, and the square's own curves cover another share.
    EXPECT_GT(largest_move(map, kind, orders), 0.05);
    const double undistorted = curve_surface_fill_rate(kind, orders, width, CurveSurface::kPlane, 2000, 1e-5).fill_rate;
    EXPECT_GT(std::fabs(rate.fill_rate - undistorted), 0.01 * undistorted);
  }
}

TEST(SurfaceFillRate, OnAFlatMeshPatchItIsThePlanarUnionOfTheDrawnCurves) {
  // A flat trapezoid (base 3, top 1.5, height 1: area 2.25) as 12 x 12 cells, inner vertices moved by
  // up to a fifth of a cell. Its border goes onto the square's by arc length, which no affine map
  // does, so the flattening is uneven inside (on a square patch mean-value flattening would give the
  // identity: it reproduces linear maps). No stroke reaches a side: the curves keep an eighth of the
  // square from its border.
  TriMesh mesh;
  const int cells = 12;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      const double y = -0.5 + double(j) / cells, half = 1.5 - 0.75 * j / cells, step = 2 * half / cells;
      const bool inner = i > 0 && i < cells && j > 0 && j < cells;
      const double dx = inner ? 0.2 * step * std::sin(12.9898 * i + 78.233 * j) : 0;
      const double dy = inner ? 0.2 / cells * std::cos(39.3468 * i + 11.135 * j) : 0;
      mesh.positions_mm.push_back({-half + i * step + dx, y + dy, 0});
    }
  test::append_grid_triangles(mesh, cells);
  const curves::SurfaceMap map = mesh_patch_map(mesh, "trapezoid");
  const double width = 0.06, r = width / 2;
  const std::vector<int> orders{2, 3};
  const SurfaceFillRate rate = curve_surface_fill_rate(CurveKind::kHilbert, orders, width, map, 2000, 1e-5);
  const std::vector<DrawnCurve> drawn = curve_points(CurveKind::kHilbert, orders, map, 1e-5);
  const double planar = round_strokes_area(drawn, r, {-1.5, -0.5}, {1.5, 0.5}) / 2.25;
  EXPECT_NEAR(rate.area, 2.25, 1e-4);
  EXPECT_NEAR(rate.fill_rate, planar, 0.0005 * planar);
  EXPECT_GT(planar, 0.05);
  EXPECT_GT(largest_move(map, CurveKind::kHilbert, orders), 0.1);
}

TEST(SurfaceFillRate, RefusesBadOptionsOnAPatch) {
  const curves::SurfaceMap map = curves::bspline_map(distorted_square());
  EXPECT_THROW(curve_surface_fill_rate(CurveKind::kHilbert, {2}, 0, map, 0, 0.01), InvalidInput);
  EXPECT_THROW(curve_surface_fill_rate(CurveKind::kHilbert, {2}, 0.1, map, 8, 0.01), InvalidInput);
}

}  // namespace
}  // namespace lacuna
