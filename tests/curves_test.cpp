// Space-filling curves: counts and steps from the definitions, exact union areas against hand
// computations and sampling, points on their surfaces, the cube tour's joints, adaptive subdivision.
#include "curves/curves.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <vector>

#include "errors.h"

namespace lacuna {
namespace {

using curves::CurveKind;
using curves::Polyline2;
using curves::Polyline3;

double length2(const Vec2d& v) { return std::hypot(v.x, v.y); }
size_t segment_count(const Polyline2& p) {
  return p.points.empty() ? 0 : (p.closed ? p.points.size() : p.points.size() - 1);
}

// Whether closed segments ab and cd share a point (exact for dyadic coordinates).
bool segments_meet(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d) {
  auto orient = [](const Vec2d& p, const Vec2d& q, const Vec2d& r) {
    const double v = cross2(q - p, r - p);
    return (v > 0) - (v < 0);
  };
  auto on = [](const Vec2d& p, const Vec2d& q, const Vec2d& r) {  // r on segment pq, given collinear
    return std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y &&
           r.y <= std::max(p.y, q.y);
  };
  const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && on(a, b, c)) || (o2 == 0 && on(a, b, d)) || (o3 == 0 && on(c, d, a)) || (o4 == 0 && on(c, d, b));
}

TEST(Curves, HilbertFromDefinition) {
  const Polyline2 h1 = curves::hilbert(1);
  const std::vector<Vec2d> expected{{0.5, 0.5}, {-0.5, 0.5}, {-0.5, -0.5}, {0.5, -0.5}};
  EXPECT_EQ(h1.points, expected);
  for (int k = 1; k <= 6; ++k) {
    const Polyline2 c = curves::hilbert(k);
    const int64_t n = int64_t(1) << k;
    const double d = 1.0 / n, h = 2 * d;
    ASSERT_EQ(c.points.size(), size_t(n * n)) << k;
    EXPECT_FALSE(c.closed);
    EXPECT_EQ(c.points.front(), (Vec2d{1 - d, 1 - d})) << k;
    EXPECT_EQ(c.points.back(), (Vec2d{1 - d, -(1 - d)})) << k;
    std::vector<int> visits(size_t(n * n), 0);
    for (size_t i = 0; i < c.points.size(); ++i) {
      const Vec2d p = c.points[i];
      const double ix = (p.x + 1) / h - 0.5, iy = (p.y + 1) / h - 0.5;  // cell indices, integers
      ASSERT_TRUE(ix == std::floor(ix) && iy == std::floor(iy) && ix >= 0 && iy >= 0 && ix < n && iy < n) << k;
      ++visits[size_t(iy) * n + size_t(ix)];
      if (i == 0) continue;
      const Vec2d s = p - c.points[i - 1];
      EXPECT_TRUE((std::fabs(s.x) == h && s.y == 0) || (s.x == 0 && std::fabs(s.y) == h)) << k << " step " << i;
    }
    EXPECT_TRUE(std::all_of(visits.begin(), visits.end(), [](int v) { return v == 1; })) << k;
    // Mirrored in Y and traversed backwards, H_k is itself (the cube tour relies on it).
    std::vector<Vec2d> mirrored;
    for (auto p = c.points.rbegin(); p != c.points.rend(); ++p) mirrored.push_back({p->x, -p->y});
    EXPECT_EQ(mirrored, c.points) << k;
  }
}

TEST(Curves, SierpinskiFromDefinition) {
  for (int k = 1; k <= 5; ++k) {
    const Polyline2 c = curves::sierpinski(k);
    const double h = 1.0 / double(int64_t(1) << (k + 1));
    const size_t n = size_t(1) << (2 * (k + 1));
    ASSERT_TRUE(c.closed);
    ASSERT_EQ(c.points.size(), n) << k;  // closed: as many segments as points
    EXPECT_EQ(segment_count(c), n);
    EXPECT_EQ(c.points.front(), (Vec2d{-1 + 2 * h, 1 - h})) << k;
    for (size_t i = 0; i < n; ++i) {
      const Vec2d p = c.points[i], s = c.points[(i + 1) % n] - p;
      EXPECT_TRUE(std::fabs(p.x) < 1 && std::fabs(p.y) < 1);
      const bool axis = (std::fabs(s.x) == 2 * h && s.y == 0) || (s.x == 0 && std::fabs(s.y) == 2 * h);
      const bool diagonal = std::fabs(s.x) == h && std::fabs(s.y) == h;
      EXPECT_TRUE(axis || diagonal) << k << " step " << i;
    }
    // No self-contact: non-adjacent segments share no point. Segments binned by a grid of cell 2h.
    const int cells = int(std::lround(1 / h));
    std::map<std::pair<int, int>, std::vector<size_t>> grid;
    for (size_t i = 0; i < n; ++i) {
      const Vec2d a = c.points[i], b = c.points[(i + 1) % n];
      const int x0 = int(std::floor((std::min(a.x, b.x) + 1) / (2 * h))),
                x1 = int(std::floor((std::max(a.x, b.x) + 1) / (2 * h)));
      const int y0 = int(std::floor((std::min(a.y, b.y) + 1) / (2 * h))),
                y1 = int(std::floor((std::max(a.y, b.y) + 1) / (2 * h)));
      for (int x = x0; x <= std::min(x1, cells - 1); ++x)
        for (int y = y0; y <= std::min(y1, cells - 1); ++y) grid[{x, y}].push_back(i);
    }
    size_t contacts = 0, pairs = 0;
    for (const auto& cell : grid)
      for (size_t u = 0; u < cell.second.size(); ++u)
        for (size_t v = u + 1; v < cell.second.size(); ++v) {
          const size_t i = cell.second[u], j = cell.second[v];
          if ((i + 1) % n == j || (j + 1) % n == i) continue;
          ++pairs;
          contacts += segments_meet(c.points[i], c.points[(i + 1) % n], c.points[j], c.points[(j + 1) % n]);
        }
    EXPECT_GT(pairs, 0u);
    EXPECT_EQ(contacts, 0u) << k;
  }
}

// Segments of a superposition on one line that overlap in positive length, as (order, order) pairs.
std::set<std::pair<int, int>> collinear_overlaps(const std::vector<curves::Curve2>& set) {
  // Key: direction class and the line's offset; exact for dyadic coordinates.
  std::map<std::pair<int, double>, std::vector<std::tuple<double, double, int>>> lines;
  for (const auto& c : set) {
    const auto& p = c.polyline.points;
    for (size_t i = 0; i < segment_count(c.polyline); ++i) {
      const Vec2d a = p[i], b = p[(i + 1) % p.size()], d = b - a;
      int kind;
      double offset, s0, s1;
      if (d.y == 0) {
        kind = 0, offset = a.y, s0 = a.x, s1 = b.x;
      } else if (d.x == 0) {
        kind = 1, offset = a.x, s0 = a.y, s1 = b.y;
      } else if (d.x == d.y) {
        kind = 2, offset = a.y - a.x, s0 = a.x, s1 = b.x;
      } else {
        if (d.x != -d.y) ADD_FAILURE() << "a step that is neither axis-parallel nor diagonal";
        kind = 3, offset = a.y + a.x, s0 = a.x, s1 = b.x;
      }
      lines[{kind, offset}].emplace_back(std::min(s0, s1), std::max(s0, s1), c.order);
    }
  }
  std::set<std::pair<int, int>> out;
  for (auto& line : lines) {
    auto& spans = line.second;
    std::sort(spans.begin(), spans.end());
    for (size_t i = 0; i < spans.size(); ++i)
      for (size_t j = i + 1; j < spans.size() && std::get<0>(spans[j]) < std::get<1>(spans[i]); ++j)
        out.insert({std::get<2>(spans[i]), std::get<2>(spans[j])});
  }
  return out;
}

TEST(Curves, SuperpositionsNeverRunAlongEachOther) {
  const auto hilbert = curves::superposition(CurveKind::kHilbert, {1, 2, 3, 4, 5, 6});
  ASSERT_EQ(hilbert.size(), 6u);
  EXPECT_EQ(hilbert[3].order, 4);
  EXPECT_EQ(hilbert[3].polyline.points.size(), 256u);
  EXPECT_TRUE(collinear_overlaps(hilbert).empty());
  const auto sierpinski = curves::superposition(CurveKind::kSierpinski, {1, 2, 3, 4, 5});
  EXPECT_TRUE(collinear_overlaps(sierpinski).empty());
  // The check does find overlaps: a curve drawn twice (as orders 1 and 2) overlaps itself.
  auto doubled = curves::superposition(CurveKind::kHilbert, {1, 2});
  doubled[1].polyline = doubled[0].polyline;
  EXPECT_EQ(collinear_overlaps(doubled), (std::set<std::pair<int, int>>{{1, 2}}));
  EXPECT_THROW(curves::superposition(CurveKind::kHilbert, {2, 3, 2}), InvalidInput);
  EXPECT_THROW(curves::superposition(CurveKind::kHilbert, {}), InvalidInput);
  EXPECT_THROW(curves::hilbert(0), InvalidInput);
  EXPECT_THROW(curves::sierpinski(12), InvalidInput);
}

TEST(Curves, Hilbert3dFromDefinition) {
  for (int k = 1; k <= 4; ++k) {
    const Polyline3 c = curves::hilbert3d(k);
    const int n = 1 << k;
    const double h = 2.0 / n;
    ASSERT_EQ(c.points.size(), size_t(n) * n * n) << k;
    EXPECT_EQ(c.points.front(), (Vec3d{-1 + h / 2, -1 + h / 2, -1 + h / 2})) << k;
    EXPECT_EQ(c.points.back(), (Vec3d{1 - h / 2, -1 + h / 2, -1 + h / 2})) << k;
    std::vector<int> visits(size_t(n) * n * n, 0);
    for (size_t i = 0; i < c.points.size(); ++i) {
      size_t cell = 0;
      for (int a = 2; a >= 0; --a) {
        const double index = (c.points[i][a] + 1) / h - 0.5;
        ASSERT_TRUE(index == std::floor(index) && index >= 0 && index < n);
        cell = cell * n + size_t(index);
      }
      ++visits[cell];
      if (i == 0) continue;
      const Vec3d s = c.points[i] - c.points[i - 1];
      const int moved = (s.x != 0) + (s.y != 0) + (s.z != 0);
      EXPECT_TRUE(moved == 1 && norm(s) == h) << k << " step " << i;
    }
    EXPECT_TRUE(std::all_of(visits.begin(), visits.end(), [](int v) { return v == 1; })) << k;
  }
  const auto set = curves::superposition3d({2, 3});
  ASSERT_EQ(set.size(), 2u);
  EXPECT_EQ(set[1].polyline.points.size(), 512u);
}

Polyline2 segment(const Vec2d& a, const Vec2d& b) { return Polyline2{{a, b}, false}; }

TEST(FillRate, SingleStrokes) {
  // Inside the square: w (L + w).
  EXPECT_NEAR(curves::convex_union_area(curves::strokes({segment({-0.5, 0.2}, {0.5, 0.2})}, 0.1), {-1, -1}, {1, 1}),
              0.1 * 1.1, 1e-14);
  EXPECT_NEAR(curves::fill_rate_exact({segment({-0.5, -0.5}, {0.5, 0.5})}, 0.1), 0.1 * (std::sqrt(2.0) + 0.1) / 4,
              1e-14);
  // Through the right side: x in [-0.2, 1.1] clipped to [-0.2, 1], y in [-0.2, 0.2].
  EXPECT_NEAR(curves::fill_rate_exact({segment({0, 0}, {0.9, 0})}, 0.4), 1.2 * 0.4 / 4, 1e-14);
  // Wholly outside.
  EXPECT_EQ(curves::fill_rate_exact({segment({2, 2}, {3, 2})}, 0.4), 0.0);
  // The same stroke twice counts once.
  EXPECT_NEAR(curves::fill_rate_exact({segment({0, 0}, {0.5, 0}), segment({0.5, 0}, {0, 0})}, 0.1), 0.1 * 0.6 / 4,
              1e-14);
  EXPECT_THROW(curves::strokes({segment({0, 0}, {1, 0})}, 0), InvalidInput);
}

TEST(FillRate, HilbertOrderOneByHand) {
  const Polyline2 h1 = curves::hilbert(1);
  // w = 0.5: three strokes of 0.5 x 1.5, the two joints overlap in 0.5 x 0.5, top and bottom are apart:
  // 3 * 0.75 - 2 * 0.25 = 1.75.
  EXPECT_NEAR(curves::fill_rate_exact({h1}, 0.5), 1.75 / 4, 1e-14);
  // w = 0.8: 3 * 0.8 * 1.8 - 2 * 0.64 = 3.04.
  EXPECT_NEAR(curves::fill_rate_exact({h1}, 0.8), 3.04 / 4, 1e-14);
  // w = 1: the top and bottom strokes are [-1, 1] x [0, 1] and [-1, 1] x [-1, 0]: the whole square.
  EXPECT_NEAR(curves::fill_rate_exact({h1}, 1), 1.0, 1e-14);
  // w = 1.5: strokes reach past the square; clipped, the whole square.
  EXPECT_NEAR(curves::fill_rate_exact({h1}, 1.5), 1.0, 1e-14);
  EXPECT_NEAR(curves::fill_rate_estimate({h1}, 0.5), 3 * 0.5 / 4, 1e-15);
}

TEST(FillRate, SingleHilbertCurveIsLengthTimesWidthPlusOneCap) {
  // For w below the step h, strokes overlap only at the 4^k - 2 joints (w^2 each): the union is
  // w (4^k - 1) h + 4^k w^2 - (4^k - 2) w^2 = w L + w^2.
  for (int k = 1; k <= 5; ++k) {
    const double h = 2.0 / (1 << k), w = h / 4;
    const double length = (std::pow(4.0, k) - 1) * h;
    EXPECT_NEAR(curves::fill_rate_exact({curves::hilbert(k)}, w), (w * length + w * w) / 4, 1e-13) << k;
  }
}

// The fraction of a 2000 x 2000 grid of sample points inside some stroke. The points sit off the cells'
// centres so that none lies on a stroke's edge (those are at dyadic positions +- w/2).
double sampled_fill_rate(const std::vector<Polyline2>& set, double w) {
  const int n = 2000;
  const double cell = 2.0 / n;
  std::vector<char> inside(size_t(n) * n, 0);
  for (const Polyline2& c : set)
    for (size_t i = 0; i < segment_count(c); ++i) {
      const Vec2d a = c.points[i], b = c.points[(i + 1) % c.points.size()], d = b - a;
      const double L = length2(d), reach = (L + w) / 2 * std::sqrt(2.0);
      const Vec2d mid = (a + b) * 0.5;
      const int x0 = std::max(0, int((mid.x - reach + 1) / cell)),
                x1 = std::min(n - 1, int((mid.x + reach + 1) / cell));
      const int y0 = std::max(0, int((mid.y - reach + 1) / cell)),
                y1 = std::min(n - 1, int((mid.y + reach + 1) / cell));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const Vec2d p = Vec2d{-1 + (x + 0.37) * cell, -1 + (y + 0.37) * cell} - mid;
          const double along = (p.x * d.x + p.y * d.y) / L, across = cross2(d, p) / L;
          if (std::fabs(along) <= (L + w) / 2 && std::fabs(across) <= w / 2) inside[size_t(y) * n + x] = 1;
        }
    }
  return double(std::count(inside.begin(), inside.end(), 1)) / (double(n) * n);
}

// The surface's area and the tubes' footprint, integrated over the whole square in one call.
curves::SurfaceCoverage whole_coverage(const curves::SurfaceMap& map, const std::vector<Polyline3>& lines, double radius,
                                       int n) {
  return curves::surface_coverage(map, curves::TubeFootprint(lines, radius), n, 0, n);
}

TEST(FillRate, SurfaceAreasMatchTheClosedForms) {
  const std::vector<Polyline3> none;
  // The sphere's image of the square: the area element of inverse stereographic projection is
  // 4 / (1 + X^2 + Y^2)^2; integrated over Y in closed form, over X by Simpson's rule.
  double sphere = 0;
  const int steps = 20000;
  for (int i = 0; i <= steps; ++i) {
    const double x = -1 + 2.0 * i / steps, a2 = 1 + x * x, a = std::sqrt(a2);
    const double inner = 1 / (a2 * (a2 + 1)) + std::atan(1 / a) / (a2 * a);
    sphere += inner * (i == 0 || i == steps ? 1 : i % 2 ? 4 : 2);
  }
  sphere *= 4 * (2.0 / steps) / 3;
  // The whole cylinder, torus (major radius 1.5, minor 1) and cone (slant sqrt 5), a cube's face.
  const std::pair<curves::SurfaceMap, double> surfaces[] = {
      {curves::sphere_map(), sphere},
      {curves::cylinder_map(), 4 * M_PI},
      {curves::torus_map(), 4 * M_PI * M_PI * 1.5},
      {curves::cone_map(), M_PI * std::sqrt(5.0)},
      {curves::cube_face_map(2), 4.0}};
  for (const auto& [map, area] : surfaces) {
    const curves::SurfaceCoverage c = whole_coverage(map, {Polyline3{{Vec3d{9, 9, 9}}, false}}, 0.01, 800);
    EXPECT_NEAR(c.area, area, 1e-4 * area) << map.name;
    EXPECT_EQ(c.covered_area, 0) << map.name;
    EXPECT_EQ(c.samples, 800u * 800u);
  }
  EXPECT_THROW(curves::TubeFootprint(none, 0), InvalidInput);
  EXPECT_THROW(whole_coverage(curves::sphere_map(), none, 0.1, 8), InvalidInput);
}

TEST(FillRate, OnTheCylinderItIsThePlanarRateUnrolled) {
  // The cylinder is the rectangle (-pi, pi) x (-1, 1) rolled up: tubes along the curves drawn on it
  // cover what round-ended strokes along the unrolled curves cover of the rectangle (to the chord's
  // bulge, (r / 1)^2 / 24 relatively). The planar union here is exact (convex_union_area) with each
  // segment's rectangle and a 128-gon at each point.
  const double r = 0.03;
  for (const auto& [kind, order] : {std::pair{CurveKind::kHilbert, 3}, std::pair{CurveKind::kSierpinski, 2}}) {
    const std::vector<Polyline2> planar = curves::polylines_of(curves::superposition(kind, {order}));
    curves::MapOptions options;
    options.tolerance_mm = 1e-6;
    std::vector<Polyline3> mapped;
    std::vector<std::vector<Vec2d>> strokes;
    for (const Polyline2& line : planar) {
      mapped.push_back(curves::map_polyline(line, curves::cylinder_map(), options));
      const size_t n = line.points.size();
      auto unrolled = [&](size_t i) { return Vec2d{M_PI * line.points[i % n].x, line.points[i % n].y}; };
      for (size_t i = 0; i < n; ++i) {
        std::vector<Vec2d> disk;
        for (int k = 0; k < 128; ++k)
          disk.push_back(unrolled(i) + Vec2d{r * std::cos(2 * M_PI * k / 128), r * std::sin(2 * M_PI * k / 128)});
        strokes.push_back(disk);
        if (i + 1 == n && !line.closed) break;
        const Vec2d a = unrolled(i), b = unrolled(i + 1), t = (b - a) * (1 / std::hypot(b.x - a.x, b.y - a.y));
        const Vec2d side{-t.y * r, t.x * r};
        strokes.push_back({a - side, b - side, b + side, a + side});
      }
    }
    const double planar_rate = curves::convex_union_area(strokes, {-M_PI - 1, -2}, {M_PI + 1, 2}) / (4 * M_PI);
    const curves::SurfaceCoverage c = whole_coverage(curves::cylinder_map(), mapped, r, 2000);
    EXPECT_NEAR(c.area, 4 * M_PI, 1e-4);
    EXPECT_NEAR(c.fill_rate(), planar_rate, 0.002 * planar_rate) << "order " << order;
    EXPECT_GT(planar_rate, 0.05);
  }
}

TEST(FillRate, SuperpositionAgainstSampling) {
  const auto hilbert = curves::polylines_of(curves::superposition(CurveKind::kHilbert, {1, 2, 3, 4}));
  const double exact = curves::fill_rate_exact(hilbert, 0.02);
  EXPECT_NEAR(exact, sampled_fill_rate(hilbert, 0.02), 0.01 * exact);
  EXPECT_GE(curves::fill_rate_estimate(hilbert, 0.02), exact);
  // Diagonal strokes too.
  const auto sierpinski = curves::polylines_of(curves::superposition(CurveKind::kSierpinski, {1, 2, 3}));
  const double exact_s = curves::fill_rate_exact(sierpinski, 0.03);
  EXPECT_NEAR(exact_s, sampled_fill_rate(sierpinski, 0.03), 0.01 * exact_s);
  EXPECT_GE(curves::fill_rate_estimate(sierpinski, 0.03), exact_s);
  // Wide diagonal strokes reaching out of the square, clipped.
  const std::vector<Polyline2> wide{curves::sierpinski(1)};
  const double exact_w = curves::fill_rate_exact(wide, 0.6);
  EXPECT_NEAR(exact_w, sampled_fill_rate(wide, 0.6), 0.01 * exact_w);
  EXPECT_LT(exact_w, 0.9);
}

TEST(Surfaces, PointsLieOnTheirSurfaces) {
  const auto sphere = curves::sphere_map(), cylinder = curves::cylinder_map(), torus = curves::torus_map(),
             cone = curves::cone_map();
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const double X = -1 + 0.1 * i, Y = -1 + 0.1 * j;
      EXPECT_NEAR(norm(sphere.point(X, Y)), 1, 1e-12);
      const Vec3d c = cylinder.point(X, Y);
      EXPECT_NEAR(c.x * c.x + c.z * c.z, 1, 1e-12);
      EXPECT_EQ(c.y, Y);
      const Vec3d t = torus.point(X, Y);
      EXPECT_NEAR(std::pow(std::hypot(t.x, t.y) - 1.5, 2) + t.z * t.z, 1, 1e-12);
      const Vec3d k = cone.point(X, Y);
      EXPECT_NEAR(k.x * k.x + k.z * k.z, std::pow((1 - k.y) / 2, 2), 1e-12);
      // Normals: unit, outwards.
      EXPECT_NEAR(dot(curves::surface_normal(sphere, X, Y), sphere.point(X, Y)), 1, 1e-12);
      EXPECT_NEAR(norm(curves::surface_normal(torus, X, Y)), 1, 1e-12);
      EXPECT_NEAR(norm(curves::surface_normal(cone, X, Y)), 1, 1e-12);
    }
  // The seams X = -1 and X = 1 meet.
  for (double Y : {-0.75, 0.0, 0.5}) {
    EXPECT_LT(norm(cylinder.point(-1, Y) - cylinder.point(1, Y)), 1e-15);
    EXPECT_LT(norm(cone.point(-1, Y) - cone.point(1, Y)), 1e-15);
  }
  EXPECT_LT(norm(cone.point(0.3, 1) - Vec3d{0, 1, 0}), 1e-15);  // the apex
  // Cube faces: on the cube, and each face's chart is isometric.
  for (int f = 0; f < 6; ++f) {
    const auto face = curves::cube_face_map(f);
    const Vec3d p = face.point(0.25, -0.5);
    EXPECT_EQ(std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}), 1.0);
    EXPECT_EQ(norm(face.point(0.75, -0.5) - p), 0.5);
    EXPECT_EQ(norm(face.point(0.25, 0.0) - p), 0.5);
    EXPECT_EQ(dot(face.point(0, 0), face.normal(0, 0)), 1.0);
  }
  EXPECT_THROW(curves::cube_face_map(6), InvalidInput);
}

TEST(Surfaces, BSplinePatch) {
  curves::BSplinePatch bilinear;
  bilinear.degree_u = bilinear.degree_v = 1;
  bilinear.count_u = bilinear.count_v = 2;
  const Vec3d p00{0, 0, 0}, p10{2, 0, 1}, p01{0, 3, -1}, p11{1, 1, 4};
  bilinear.control_points = {p00, p10, p01, p11};
  const auto map = curves::bspline_map(bilinear);
  for (double u : {0.0, 0.1, 0.5, 0.73, 1.0})
    for (double v : {0.0, 0.25, 0.6, 1.0}) {
      const Vec3d expected = p00 * ((1 - u) * (1 - v)) + p10 * (u * (1 - v)) + p01 * ((1 - u) * v) + p11 * (u * v);
      EXPECT_LT(norm(map.point(2 * u - 1, 2 * v - 1) - expected), 1e-14) << u << " " << v;
    }
  // Degree 2, 4 x 5 control points on the plane z = 0.5 x - 0.25 y + 1 (irregular in the plane).
  curves::BSplinePatch planar;
  planar.degree_u = planar.degree_v = 2;
  planar.count_u = 4;
  planar.count_v = 5;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 4; ++i) {
      const double x = i + 0.3 * std::sin(7.0 * i + j), y = j + 0.2 * std::cos(3.0 * i * j);
      planar.control_points.push_back({x, y, 0.5 * x - 0.25 * y + 1});
    }
  const auto plane = curves::bspline_map(planar);
  for (double X = -1; X <= 1; X += 0.125)
    for (double Y = -1; Y <= 1; Y += 0.125) {
      const Vec3d p = plane.point(X, Y);
      EXPECT_NEAR(p.z, 0.5 * p.x - 0.25 * p.y + 1, 1e-12);
    }
  // Clamped knots: the corners are the corner control points.
  EXPECT_LT(norm(plane.point(-1, -1) - planar.control_points[0]), 1e-15);
  EXPECT_LT(norm(plane.point(1, 1) - planar.control_points[19]), 1e-15);
  EXPECT_LT(norm(plane.point(1, -1) - planar.control_points[3]), 1e-15);
  // The finite-difference normal follows dP/du x dP/dv: here (-0.5, 0.25, 1) normalized.
  const Vec3d n = curves::surface_normal(plane, 0.1, -0.3);
  EXPECT_LT(norm(n - Vec3d{-0.5, 0.25, 1} / std::sqrt(1.3125)), 1e-8);
  planar.control_points.pop_back();
  EXPECT_THROW(curves::bspline_map(planar), InvalidInput);
}

TEST(Surfaces, CubeHilbertTour) {
  for (int k = 1; k <= 4; ++k) {
    const double d = 1.0 / (1 << k), h = 2 * d;
    const size_t per_face = size_t(1) << (2 * k);
    // The joint on the edge shared by faces f and f + 1 is the same point in both charts.
    for (int f = 0; f < 6; ++f)
      EXPECT_EQ(curves::cube_face_map(f).point(1, -1 + d), curves::cube_face_map((f + 1) % 6).point(1 - d, 1)) << f;
    const auto loops = curves::cube_curve(CurveKind::kHilbert, k);
    ASSERT_EQ(loops.size(), 1u);
    const Polyline3& tour = loops[0];
    ASSERT_TRUE(tour.closed);
    ASSERT_EQ(tour.points.size(), 6 * per_face + 6);
    std::set<std::vector<double>> seen_points;
    std::set<std::pair<std::vector<double>, std::vector<double>>> seen_segments;
    int on_edges = 0, half_steps = 0;
    for (size_t i = 0; i < tour.points.size(); ++i) {
      const Vec3d p = tour.points[i], q = tour.points[(i + 1) % tour.points.size()];
      const int at_one = (std::fabs(p.x) == 1) + (std::fabs(p.y) == 1) + (std::fabs(p.z) == 1);
      EXPECT_TRUE(at_one == 1 || at_one == 2) << i;  // on the cube, never at a corner
      EXPECT_EQ(std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}), 1.0);
      on_edges += at_one == 2;
      // Connected: every step is one cell along one axis, or half a cell to or from an edge.
      const Vec3d s = q - p;
      EXPECT_EQ((s.x != 0) + (s.y != 0) + (s.z != 0), 1) << i;
      EXPECT_TRUE(norm(s) == h || norm(s) == d) << i;
      half_steps += norm(s) == d;
      seen_points.insert({p.x, p.y, p.z});
      std::vector<double> a{p.x, p.y, p.z}, b{q.x, q.y, q.z};
      seen_segments.insert({std::min(a, b), std::max(a, b)});
    }
    EXPECT_EQ(on_edges, 6);
    EXPECT_EQ(half_steps, 12);
    EXPECT_EQ(seen_points.size(), tour.points.size());    // no point twice
    EXPECT_EQ(seen_segments.size(), tour.points.size());  // no doubled segment
  }
  // Scaled and offset: on the box of half-size 10.5, joints on its edges.
  curves::MapOptions options;
  options.scale = 10;
  options.offset_mm = 0.5;
  const auto offset_tour = curves::cube_curve(CurveKind::kHilbert, 2, options);
  for (const Vec3d& p : offset_tour[0].points)
    EXPECT_EQ(std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}), 10.5);
  const auto loops = curves::cube_curve(CurveKind::kSierpinski, 2);
  ASSERT_EQ(loops.size(), 6u);
  for (const auto& loop : loops) {
    EXPECT_TRUE(loop.closed);
    EXPECT_EQ(loop.points.size(), 64u);
    // All on one face: the coordinate at +-1 is the same for every point.
    const Vec3d first = loop.points[0];
    const int axis = std::fabs(first.x) == 1 ? 0 : std::fabs(first.y) == 1 ? 1 : 2;
    for (const Vec3d& p : loop.points) {
      EXPECT_EQ(p[axis], first[axis]);
      EXPECT_EQ(std::fabs(p[axis]), 1.0);
      EXPECT_LT(std::fabs(p[(axis + 1) % 3]), 1.0);
      EXPECT_LT(std::fabs(p[(axis + 2) % 3]), 1.0);
    }
  }
}

TEST(Surfaces, AdaptiveSubdivisionMeetsTolerance) {
  const auto sphere = curves::sphere_map();
  const Polyline2 h3 = curves::hilbert(3);
  size_t previous = h3.points.size();
  for (double tolerance : {0.01, 0.001, 0.0001}) {
    curves::MapOptions options;
    options.tolerance_mm = tolerance;
    const Polyline3 mapped = curves::map_polyline(h3, sphere, options);
    EXPECT_GT(mapped.points.size(), previous) << tolerance;
    previous = mapped.points.size();
    EXPECT_EQ(mapped.points.front(), sphere.point(h3.points[0].x, h3.points[0].y));
    EXPECT_EQ(mapped.points.back(), sphere.point(h3.points.back().x, h3.points.back().y));
    double worst = 0;
    for (size_t i = 0; i + 1 < mapped.points.size(); ++i) {
      EXPECT_NEAR(norm(mapped.points[i]), 1, 1e-12);
      // The chord's midpoint is within tolerance of the mapped midpoint, which is on the sphere.
      worst = std::max(worst, std::fabs(norm((mapped.points[i] + mapped.points[i + 1]) * 0.5) - 1));
    }
    EXPECT_LE(worst, tolerance);
    EXPECT_GT(worst, tolerance / 8);  // not grossly over-refined
  }
  // A closed curve stays closed, its start not repeated; with scale and offset it lies on the offset torus.
  curves::MapOptions options;
  options.scale = 2;
  options.offset_mm = 0.25;
  options.tolerance_mm = 0.005;
  const Polyline2 s2 = curves::sierpinski(2);
  const Polyline3 on_torus = curves::map_polyline(s2, curves::torus_map(), options);
  EXPECT_TRUE(on_torus.closed);
  EXPECT_GT(on_torus.points.size(), s2.points.size());
  EXPECT_NE(on_torus.points.back(), on_torus.points.front());
  for (const Vec3d& p : on_torus.points)
    EXPECT_NEAR(std::pow(std::hypot(p.x, p.y) - 3, 2) + p.z * p.z, 2.25 * 2.25, 1e-12);
  // Offset cylinder and cone: radius 2.25; distance 0.25 from the cone of base radius 2 and apex (0, 2, 0).
  const Polyline3 on_cylinder = curves::map_polyline(s2, curves::cylinder_map(), options);
  for (const Vec3d& p : on_cylinder.points) EXPECT_NEAR(std::hypot(p.x, p.z), 2.25, 1e-12);
  const Polyline3 on_cone = curves::map_polyline(s2, curves::cone_map(), options);
  for (const Vec3d& p : on_cone.points) EXPECT_NEAR((2 * std::hypot(p.x, p.z) + p.y - 2) / std::sqrt(5.0), 0.25, 1e-12);
  // max_depth bounds the halvings: depth 0 maps the points only.
  options.max_depth = 0;
  EXPECT_EQ(curves::map_polyline(s2, curves::torus_map(), options).points.size(), s2.points.size());
  options.tolerance_mm = 0;
  EXPECT_THROW(curves::map_polyline(s2, curves::torus_map(), options), InvalidInput);
}

}  // namespace
}  // namespace lacuna
