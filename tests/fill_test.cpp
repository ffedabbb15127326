// Random fractal filling: the Hurwitz zeta function against closed forms and identities, the generator's
// determinism, detected motif symmetries, placements checked by independent exact geometry (no overlaps,
// gaps, containment, the area law), the 17 wallpaper groups (tiling by the fundamental region, invariance of
// the replicated pattern under every operation), and spheres in 3D.
#include "fill/fill.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "errors.h"
#include "fill/motif_file.h"
#include "fill/wallpaper.h"
#include "tests/test_support.h"

namespace lacuna {
namespace {

using fill::Motif2;
using fill::Placement2;

constexpr double kPi = 3.14159265358979323846;

double dot2(const Vec2d& a, const Vec2d& b) { return a.x * b.x + a.y * b.y; }
double len(const Vec2d& v) { return std::hypot(v.x, v.y); }

// ---- independent geometry ----

// The motif's outline under the placement, written out from the definition of Placement2.
std::vector<Vec2d> outline_of(const Motif2& m, const Placement2& p) {
  std::vector<Vec2d> out;
  for (const Vec2d& v : m.outline) {
    const Vec2d w{v.x * p.scale, (p.mirrored ? -v.y : v.y) * p.scale};
    out.push_back({p.center_mm.x + std::cos(p.angle_rad) * w.x - std::sin(p.angle_rad) * w.y,
                   p.center_mm.y + std::sin(p.angle_rad) * w.x + std::cos(p.angle_rad) * w.y});
  }
  return out;
}

double point_segment(const Vec2d& p, const Vec2d& a, const Vec2d& b) {
  const Vec2d ab = b - a;
  const double t = std::clamp(dot2(p - a, ab) / dot2(ab, ab), 0.0, 1.0);
  return len(p - (a + ab * t));
}

bool proper_cross(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d) {
  const double o1 = cross2(b - a, c - a), o2 = cross2(b - a, d - a), o3 = cross2(d - c, a - c), o4 = cross2(d - c, b - c);
  return ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
}

bool inside(const std::vector<Vec2d>& poly, const Vec2d& p) {  // winding number
  int w = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec2d a = poly[i], b = poly[(i + 1) % poly.size()];
    if (a.y <= p.y && b.y > p.y && cross2(b - a, p - a) > 0) ++w;
    if (a.y > p.y && b.y <= p.y && cross2(b - a, p - a) < 0) --w;
  }
  return w != 0;
}

// The distance between two polygons (0 when they overlap), by brute force over all edge pairs.
double polygon_distance(const std::vector<Vec2d>& a, const std::vector<Vec2d>& b) {
  double d = HUGE_VAL;
  for (size_t i = 0; i < a.size(); ++i)
    for (size_t j = 0; j < b.size(); ++j) {
      const Vec2d p = a[i], q = a[(i + 1) % a.size()], r = b[j], s = b[(j + 1) % b.size()];
      if (proper_cross(p, q, r, s)) return 0;
      d = std::min({d, point_segment(p, r, s), point_segment(q, r, s), point_segment(r, p, q), point_segment(s, p, q)});
    }
  if (inside(a, b[0]) || inside(b, a[0])) return 0;
  return d;
}

double motif_distance(const Motif2& m, const Placement2& p, const Placement2& q) {
  if (m.kind == Motif2::Kind::kCircle) {
    const double r = 1 / std::sqrt(kPi);
    return len(p.center_mm - q.center_mm) - r * (p.scale + q.scale);
  }
  return polygon_distance(outline_of(m, p), outline_of(m, q));
}

double bounding(const Motif2& m, const Placement2& p) {
  if (m.kind == Motif2::Kind::kCircle) return p.scale / std::sqrt(kPi);
  double r = 0;
  for (const Vec2d& v : m.outline) r = std::max(r, len(v));
  return r * p.scale;
}

// Every pair of placements at least `gap` apart (pairs whose bounding circles are that far apart skipped).
void expect_separated(const Motif2& m, const std::vector<Placement2>& ps, double gap) {
  std::vector<size_t> order(ps.size());
  for (size_t i = 0; i < ps.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t i, size_t j) { return ps[i].center_mm.x < ps[j].center_mm.x; });
  double rmax = 0;
  for (const Placement2& p : ps) rmax = std::max(rmax, bounding(m, p));
  int failures = 0;
  for (size_t x = 0; x < order.size(); ++x)
    for (size_t y = x + 1; y < order.size(); ++y) {
      const Placement2 &p = ps[order[x]], &q = ps[order[y]];
      if (q.center_mm.x - p.center_mm.x > 2 * rmax + gap) break;
      if (len(p.center_mm - q.center_mm) >= bounding(m, p) + bounding(m, q) + gap) continue;
      const double d = motif_distance(m, p, q);
      if (d < gap - 1e-9 && failures++ < 5)
        ADD_FAILURE() << "motifs " << order[x] << " and " << order[y] << " at distance " << d << " < gap " << gap;
    }
  EXPECT_EQ(failures, 0);
}

double law_fraction(double c, double N, size_t k) {
  double f = 0;
  const double z = fill::hurwitz_zeta(c, N);
  for (size_t i = 0; i < k; ++i) f += 1 / (z * std::pow(N + double(i), c));
  return f;
}

void expect_area_law(const fill::FillResult2& r, double A, double c, double N, double factor_of_stabilizer = 1) {
  const double z = fill::hurwitz_zeta(c, N);
  for (size_t i = 0; i < r.motifs.size(); ++i) {
    const double expected = A / (z * std::pow(N + double(i), c)) * (factor_of_stabilizer > 0 ? r.motifs[i].stabilizer_order : 1);
    EXPECT_NEAR(r.motifs[i].area_mm2, expected, 1e-12 * expected) << i;
    EXPECT_NEAR(r.motifs[i].scale * r.motifs[i].scale, r.motifs[i].area_mm2, 1e-12 * expected) << i;
  }
  EXPECT_EQ(r.fill_fraction, law_fraction(c, N, r.motifs.size()));
}

// ---- zeta and the generator ----

TEST(Fill, HurwitzZetaClosedForms) {
  const double z2 = fill::hurwitz_zeta(2, 1), z4 = fill::hurwitz_zeta(4, 1);
  EXPECT_NEAR(z2, kPi * kPi / 6, 1e-12 * z2);
  EXPECT_NEAR(z4, std::pow(kPi, 4) / 90, 1e-12 * z4);
  for (double s : {2.0, 3.0, 1.3, 7.5}) {
    const double half = fill::hurwitz_zeta(s, 0.5), one = fill::hurwitz_zeta(s, 1);
    EXPECT_NEAR(half, (std::pow(2, s) - 1) * one, 1e-12 * half) << s;
  }
  for (double s : {1.05, 1.3, 2.0, 4.5, 30.0})
    for (double q : {0.01, 0.3, 1.0, 1.7, 5.0, 40.0}) {
      const double z = fill::hurwitz_zeta(s, q);
      EXPECT_NEAR(z - fill::hurwitz_zeta(s, q + 1), std::pow(q, -s), 1e-12 * z) << s << " " << q;
    }
  // zeta(3, 1) is Apery's constant.
  EXPECT_NEAR(fill::hurwitz_zeta(3, 1), 1.2020569031595942854, 1e-15);
  EXPECT_THROW(fill::hurwitz_zeta(1, 1), InvalidInput);
  EXPECT_THROW(fill::hurwitz_zeta(0.5, 1), InvalidInput);
  EXPECT_THROW(fill::hurwitz_zeta(2, 0), InvalidInput);
  EXPECT_THROW(fill::hurwitz_zeta(2, -1), InvalidInput);
  EXPECT_THROW(fill::hurwitz_zeta(NAN, 1), InvalidInput);
}

TEST(Fill, RandomIsDeterministic) {
  fill::Random a(42), b(42), c(43);
  bool differ = false;
  for (int i = 0; i < 1000; ++i) {
    const uint64_t x = a.next();
    EXPECT_EQ(x, b.next());
    differ = differ || x != c.next();
  }
  EXPECT_TRUE(differ);
  // xoshiro256** seeded by splitmix64 from 7, computed independently from the published definitions.
  fill::Random first(7);
  EXPECT_EQ(first.next(), 0xb358faf74ef9765aull);
  EXPECT_EQ(first.next(), 0x475c3d964f482cd2ull);
  EXPECT_EQ(first.next(), 0xd6f1d349952c7996ull);
  fill::Random r(7);
  double sum = 0;
  for (int i = 0; i < 1000000; ++i) {
    const double u = r.uniform();
    ASSERT_TRUE(u >= 0 && u < 1);
    sum += u;
  }
  EXPECT_NEAR(sum / 1e6, 0.5, 0.002);
}

// ---- motifs ----

TEST(Fill, MotifSymmetries) {
  const Motif2 square = fill::polygon_motif({{0, 0}, {2, 0}, {2, 2}, {0, 2}});
  EXPECT_EQ(square.rotation_order, 4);
  EXPECT_EQ(square.mirror_angles_rad.size(), 4u);
  const Motif2 triangle = fill::polygon_motif({{0, 0}, {1, 0}, {0.5, std::sqrt(3.0) / 2}});
  EXPECT_EQ(triangle.rotation_order, 3);
  EXPECT_EQ(triangle.mirror_angles_rad.size(), 3u);
  // A clockwise arrow with a collinear extra point: symmetric about the x axis only.
  const Motif2 arrow = fill::polygon_motif({{0, 1}, {3, 1}, {3, 2}, {5, 0}, {3, -2}, {3, -1}, {0, -1}, {0, 0}});
  EXPECT_EQ(arrow.rotation_order, 1);
  ASSERT_EQ(arrow.mirror_angles_rad.size(), 1u);
  EXPECT_NEAR(arrow.mirror_angles_rad[0], 0, 1e-12);
  EXPECT_FALSE(arrow.convex);
  EXPECT_EQ(arrow.outline.size(), 7u);
  // A heart: symmetric about the y axis.
  std::vector<Vec2d> heart;
  for (int k = 0; k < 40; ++k) {
    const double t = 2 * kPi * k / 40;
    heart.push_back({16 * std::pow(std::sin(t), 3), 13 * std::cos(t) - 5 * std::cos(2 * t) - 2 * std::cos(3 * t) - std::cos(4 * t)});
  }
  const Motif2 h = fill::polygon_motif(heart);
  EXPECT_EQ(h.rotation_order, 1);
  ASSERT_EQ(h.mirror_angles_rad.size(), 1u);
  EXPECT_NEAR(h.mirror_angles_rad[0], kPi / 2, 1e-9);
  const Motif2 quad = fill::polygon_motif({{0, 0}, {3, 0}, {2.5, 2}, {0.3, 1.4}});
  EXPECT_EQ(quad.rotation_order, 1);
  EXPECT_TRUE(quad.mirror_angles_rad.empty());
  const Motif2 hexagon = fill::regular_polygon_motif(6);
  EXPECT_EQ(hexagon.rotation_order, 6);
  EXPECT_EQ(hexagon.mirror_angles_rad.size(), 6u);
  // A rectangle: 2-fold with two mirrors; a parallelogram: 2-fold without.
  const Motif2 rect = fill::polygon_motif({{0, 0}, {3, 0}, {3, 1}, {0, 1}});
  EXPECT_EQ(rect.rotation_order, 2);
  EXPECT_EQ(rect.mirror_angles_rad.size(), 2u);
  const Motif2 para = fill::polygon_motif({{0, 0}, {3, 0}, {4, 1}, {1, 1}});
  EXPECT_EQ(para.rotation_order, 2);
  EXPECT_TRUE(para.mirror_angles_rad.empty());
  // Normalized: area 1, centroid at the origin, counter-clockwise.
  for (const Motif2* m : {&square, &triangle, &arrow, &h, &quad, &hexagon}) {
    double a = 0, cx = 0, cy = 0;
    for (size_t i = 0; i < m->outline.size(); ++i) {
      const Vec2d p = m->outline[i], q = m->outline[(i + 1) % m->outline.size()];
      a += cross2(p, q) / 2;
      cx += (p.x + q.x) * cross2(p, q) / 6;
      cy += (p.y + q.y) * cross2(p, q) / 6;
    }
    EXPECT_NEAR(a, 1, 1e-12);
    EXPECT_NEAR(cx, 0, 1e-12);
    EXPECT_NEAR(cy, 0, 1e-12);
  }
  EXPECT_THROW(fill::polygon_motif({{0, 0}, {1, 0}}), InvalidInput);
  EXPECT_THROW(fill::polygon_motif({{0, 0}, {1, 0}, {2, 0}}), InvalidInput);
  EXPECT_THROW(fill::polygon_motif({{0, 0}, {1, 1}, {1, 0}, {0, 1}}), InvalidInput);  // bow tie
  EXPECT_THROW(fill::polygon_motif({{0, 0}, {1, 0}, {NAN, 1}}), InvalidInput);
  EXPECT_THROW(fill::regular_polygon_motif(2), InvalidInput);
}

// ---- placement in a region ----

void expect_inside(const fill::FillRegion2& region, const Motif2& m, const std::vector<Placement2>& ps, double g) {
  for (size_t i = 0; i < ps.size(); ++i) {
    const Placement2& p = ps[i];
    if (m.kind == Motif2::Kind::kCircle) {
      const double r = p.scale / std::sqrt(kPi);
      const Vec2d c = p.center_mm;
      switch (region.kind) {
        case fill::FillRegion2::Kind::kRectangle:
          EXPECT_TRUE(c.x - r >= region.min_mm.x + g - 1e-12 && c.x + r <= region.max_mm.x - g + 1e-12 &&
                      c.y - r >= region.min_mm.y + g - 1e-12 && c.y + r <= region.max_mm.y - g + 1e-12) << i;
          break;
        case fill::FillRegion2::Kind::kDisk:
          EXPECT_LE(len(c - region.center_mm) + r + g, region.radius_mm + 1e-12) << i;
          break;
        case fill::FillRegion2::Kind::kPolygon: {
          EXPECT_TRUE(inside(region.polygon_mm, c)) << i;
          double d = HUGE_VAL;
          for (size_t k = 0; k < region.polygon_mm.size(); ++k)
            d = std::min(d, point_segment(c, region.polygon_mm[k], region.polygon_mm[(k + 1) % region.polygon_mm.size()]));
          EXPECT_GE(d, r + g - 1e-12) << i;
          break;
        }
      }
      continue;
    }
    const std::vector<Vec2d> o = outline_of(m, p);
    for (const Vec2d& v : o) {
      if (region.kind == fill::FillRegion2::Kind::kRectangle) {
        EXPECT_TRUE(v.x >= region.min_mm.x + g - 1e-12 && v.x <= region.max_mm.x - g + 1e-12 &&
                    v.y >= region.min_mm.y + g - 1e-12 && v.y <= region.max_mm.y - g + 1e-12) << i;
      }
      if (region.kind == fill::FillRegion2::Kind::kDisk) {
        EXPECT_LE(len(v - region.center_mm), region.radius_mm - g + 1e-12) << i;
      }
    }
    if (region.kind == fill::FillRegion2::Kind::kPolygon) {
      EXPECT_TRUE(inside(region.polygon_mm, o[0])) << i;
      // Inside a polygon, the distance to the complement is the distance between the outlines.
      double d = HUGE_VAL;
      for (size_t a = 0; a < o.size(); ++a)
        for (size_t b = 0; b < region.polygon_mm.size(); ++b)
          d = std::min({d, point_segment(o[a], region.polygon_mm[b], region.polygon_mm[(b + 1) % region.polygon_mm.size()]),
                        point_segment(region.polygon_mm[b], o[a], o[(a + 1) % o.size()])});
      EXPECT_GE(d, g - 1e-12) << i;
      bool crossing = false;
      for (size_t a = 0; a < o.size(); ++a)
        for (size_t b = 0; b < region.polygon_mm.size(); ++b)
          crossing = crossing || proper_cross(o[a], o[(a + 1) % o.size()], region.polygon_mm[b],
                                              region.polygon_mm[(b + 1) % region.polygon_mm.size()]);
      EXPECT_FALSE(crossing) << i;
    }
  }
}

void check_fill(const fill::FillRegion2& region, const Motif2& m, const fill::FillOptions& o, size_t min_count) {
  const fill::FillResult2 r = fill::fill_region(region, m, o);
  SCOPED_TRACE(r.stop_reason);
  EXPECT_GE(r.motifs.size(), min_count);
  expect_area_law(r, fill::area(region), o.c, o.N, 0);
  expect_inside(region, m, r.motifs, o.boundary_gap_mm);
  expect_separated(m, r.motifs, o.gap_mm);
  // Same seed, same placements.
  const fill::FillResult2 again = fill::fill_region(region, m, o);
  ASSERT_EQ(again.motifs.size(), r.motifs.size());
  for (size_t i = 0; i < r.motifs.size(); ++i) {
    EXPECT_EQ(again.motifs[i].center_mm, r.motifs[i].center_mm);
    EXPECT_EQ(again.motifs[i].angle_rad, r.motifs[i].angle_rad);
  }
}

TEST(Fill, CirclesInRegions) {
  fill::FillOptions o;
  o.max_count = 400;
  o.c = 1.25;
  check_fill(fill::rectangle_region({0, 0}, {20, 10}), fill::circle_motif(), o, 400);
  EXPECT_EQ(fill::fill_region(fill::rectangle_region({0, 0}, {20, 10}), fill::circle_motif(), o).stop_reason, "max_count");
  o.gap_mm = 0.01;
  o.boundary_gap_mm = 0.02;
  o.seed = 9;
  check_fill(fill::disk_region({3, -2}, 5), fill::circle_motif(), o, 400);
  // An L-shaped (non-convex) region.
  const fill::FillRegion2 l = fill::polygon_region({{0, 0}, {10, 0}, {10, 4}, {4, 4}, {4, 10}, {0, 10}});
  EXPECT_DOUBLE_EQ(fill::area(l), 64);
  check_fill(l, fill::circle_motif(), o, 400);
  // Different seeds give different fills.
  fill::FillOptions p = o;
  p.seed = 10;
  EXPECT_FALSE(fill::fill_region(l, fill::circle_motif(), o).motifs[0].center_mm ==
               fill::fill_region(l, fill::circle_motif(), p).motifs[0].center_mm);
}

TEST(Fill, PolygonsInRegions) {
  fill::FillOptions o;
  o.max_count = 150;
  o.c = 1.2;
  o.random_rotation = true;
  o.gap_mm = 0.005;
  o.boundary_gap_mm = 0.01;
  check_fill(fill::rectangle_region({0, 0}, {10, 10}), fill::regular_polygon_motif(4), o, 150);
  check_fill(fill::disk_region({0, 0}, 6), fill::regular_polygon_motif(3), o, 150);
  const Motif2 arrow = fill::polygon_motif({{0, 1}, {3, 1}, {3, 2}, {5, 0}, {3, -2}, {3, -1}, {0, -1}});
  check_fill(fill::disk_region({0, 0}, 6), arrow, o, 150);
  const fill::FillRegion2 l = fill::polygon_region({{0, 0}, {10, 0}, {10, 4}, {4, 4}, {4, 10}, {0, 10}});
  check_fill(l, arrow, o, 150);
  o.gap_mm = 0;
  o.boundary_gap_mm = 0;
  check_fill(l, fill::regular_polygon_motif(5), o, 150);
}

TEST(Fill, StopReasons) {
  fill::FillOptions o;
  o.max_trials = 1;
  o.N = 1.01;  // the first motif covers 0.82 of the square: a circle of diameter 1.02 cannot fit
  o.c = 3;
  const fill::FillResult2 r = fill::fill_region(fill::rectangle_region({0, 0}, {1, 1}), fill::circle_motif(), o);
  EXPECT_TRUE(r.motifs.empty());
  EXPECT_EQ(r.stop_reason, "max_trials: motif 0 could not be placed in 1 trials");
  EXPECT_EQ(r.fill_fraction, 0);
  fill::FillOptions m;
  m.min_area_mm2 = 0.01;
  const fill::FillResult2 s = fill::fill_region(fill::rectangle_region({0, 0}, {1, 1}), fill::circle_motif(), m);
  EXPECT_EQ(s.stop_reason, "min_area");
  // The motifs kept are exactly those of area >= 0.01: A / (zeta (N + i)^c) >= 0.01.
  size_t expected = 0;
  while (1 / (fill::hurwitz_zeta(1.3, 2) * std::pow(2.0 + double(expected), 1.3)) >= 0.01) ++expected;
  EXPECT_EQ(s.motifs.size(), expected);
  fill::FillOptions bad;
  bad.c = 1;
  EXPECT_THROW(fill::fill_region(fill::rectangle_region({0, 0}, {1, 1}), fill::circle_motif(), bad), InvalidInput);
  bad = {};
  bad.gap_mm = -1;
  EXPECT_THROW(fill::fill_region(fill::rectangle_region({0, 0}, {1, 1}), fill::circle_motif(), bad), InvalidInput);
  EXPECT_THROW(fill::rectangle_region({0, 0}, {0, 1}), InvalidInput);
  EXPECT_THROW(fill::disk_region({0, 0}, 0), InvalidInput);
}

// ---- wallpaper groups ----

constexpr fill::Group kGroups[] = {fill::Group::p1,  fill::Group::p2,   fill::Group::pm,   fill::Group::pg,
                                   fill::Group::cm,  fill::Group::pmm,  fill::Group::pmg,  fill::Group::pgg,
                                   fill::Group::cmm, fill::Group::p4,   fill::Group::p4m,  fill::Group::p4g,
                                   fill::Group::p3,  fill::Group::p3m1, fill::Group::p31m, fill::Group::p6,
                                   fill::Group::p6m};

fill::Lattice valid_lattice(fill::Group g) {
  const std::string n = fill::group_name(g);
  if (n == "p1" || n == "p2") return {{3, 0.4}, {1.1, 2.6}};
  if (n == "pm" || n == "pg" || n == "pmm" || n == "pmg" || n == "pgg") return {{3 * 0.8, 3 * 0.6}, {-2 * 0.6, 2 * 0.8}};
  if (n == "cm" || n == "cmm") return {{2.5, 0}, {2.5 * std::cos(1.1), 2.5 * std::sin(1.1)}};
  if (n == "p4" || n == "p4m" || n == "p4g") return {{2, 1}, {-1, 2}};
  return {{3, 0}, {-1.5, 1.5 * std::sqrt(3.0)}};
}

Vec2d apply_op(const fill::Affine2& m, const Vec2d& p) { return fill::apply(m, p); }

TEST(Fill, WallpaperOperations) {
  // Order of the point group and the number of operations that contain a true mirror (not only glides).
  const int orders[] = {1, 2, 2, 2, 2, 4, 4, 4, 4, 4, 8, 8, 3, 6, 6, 6, 12};
  const int mirrors[] = {0, 0, 1, 0, 1, 2, 1, 0, 2, 0, 4, 2, 0, 3, 3, 0, 6};
  for (int gi = 0; gi < 17; ++gi) {
    const fill::Group g = kGroups[gi];
    SCOPED_TRACE(fill::group_name(g));
    EXPECT_EQ(fill::group_from_name(fill::group_name(g)), g);
    const std::vector<fill::Affine2> cell = fill::cell_operations(g);
    ASSERT_EQ(int(cell.size()), orders[gi]);
    const fill::Lattice l = fill::group_lattice(g, valid_lattice(g));
    const std::vector<fill::Affine2> ops = fill::world_operations(g, l);
    int mirror_count = 0;
    for (const fill::Affine2& m : ops) {
      // An isometry: L^T L = I.
      const double a = m.linear[0][0], b = m.linear[0][1], c = m.linear[1][0], d = m.linear[1][1];
      EXPECT_NEAR(a * a + c * c, 1, 1e-12);
      EXPECT_NEAR(b * b + d * d, 1, 1e-12);
      EXPECT_NEAR(a * b + c * d, 0, 1e-12);
      // A reflection x -> L x + t + i a + j b has a mirror line when some translate of t is perpendicular to
      // its direction: (t + i a + j b) . d = 0.
      if (a * d - b * c < 0) {
        const double alpha = std::atan2(c, a) / 2;
        const Vec2d dir{std::cos(alpha), std::sin(alpha)};
        bool has = false;
        for (int i = -2; i <= 2; ++i)
          for (int j = -2; j <= 2; ++j)
            has = has || std::fabs(dot2(m.translation + l.a * double(i) + l.b * double(j), dir)) < 1e-9;
        mirror_count += has;
      }
    }
    EXPECT_EQ(mirror_count, mirrors[gi]);
    // Closed modulo the lattice: the product of two operations is an operation plus a lattice vector.
    for (const fill::Affine2& p : cell)
      for (const fill::Affine2& q : cell) {
        const Vec2d probe{0.1234, 0.3141};
        const Vec2d pq = apply_op(p, apply_op(q, probe));
        bool found = false;
        for (const fill::Affine2& r : cell) {
          const Vec2d d = pq - apply_op(r, probe);
          const Vec2d e = apply_op(p, apply_op(q, Vec2d{0.7, 0.2})) - apply_op(r, Vec2d{0.7, 0.2});
          found = found || (std::fabs(d.x - std::round(d.x)) < 1e-12 && std::fabs(d.y - std::round(d.y)) < 1e-12 &&
                            std::fabs(e.x - d.x) < 1e-12 && std::fabs(e.y - d.y) < 1e-12);
        }
        EXPECT_TRUE(found);
      }
    // The fundamental region tiles: a point of the cell lies in exactly one image of it.
    const std::vector<Vec2d> region = fill::fundamental_region(g);
    double area = 0;
    for (size_t i = 0; i < region.size(); ++i) area += cross2(region[i], region[(i + 1) % region.size()]) / 2;
    EXPECT_NEAR(area, 1.0 / orders[gi], 1e-15);
    fill::Random random(5);
    for (int s = 0; s < 300; ++s) {
      const Vec2d p{random.uniform(), random.uniform()};
      int count = 0;
      for (const fill::Affine2& m : cell)
        for (int i = -2; i <= 2; ++i)
          for (int j = -2; j <= 2; ++j) {
            std::vector<Vec2d> image;
            for (const Vec2d& v : region) image.push_back(apply_op(m, v) + Vec2d{double(i), double(j)});
            count += inside(image, p);
          }
      EXPECT_EQ(count, 1) << p.x << " " << p.y;
    }
  }
  // p3m1 has all its 3-fold centres on mirrors, p31m not the ones at (2/3, 1/3).
  for (fill::Group g : {fill::Group::p3m1, fill::Group::p31m}) {
    int through = 0;
    for (const fill::Affine2& m : fill::cell_operations(g)) {
      if (m.linear[0][0] * m.linear[1][1] - m.linear[0][1] * m.linear[1][0] > 0) continue;
      const Vec2d c{2.0 / 3, 1.0 / 3};
      const Vec2d d = apply_op(m, c) - c;
      through += std::fabs(d.x - std::round(d.x)) < 1e-12 && std::fabs(d.y - std::round(d.y)) < 1e-12;
    }
    EXPECT_EQ(through, g == fill::Group::p3m1 ? 3 : 0);
  }
}

TEST(Fill, WallpaperLatticesChecked) {
  EXPECT_THROW(fill::group_from_name("p5"), InvalidInput);
  EXPECT_THROW(fill::group_lattice(fill::Group::p1, {{1, 0}, {2, 0}}), InvalidInput);
  EXPECT_THROW(fill::group_lattice(fill::Group::pm, {{1, 0}, {0.1, 1}}), InvalidInput);
  EXPECT_THROW(fill::group_lattice(fill::Group::cmm, {{1, 0}, {0, 2}}), InvalidInput);
  EXPECT_THROW(fill::group_lattice(fill::Group::p4m, {{1, 0}, {0, 1.5}}), InvalidInput);
  EXPECT_THROW(fill::group_lattice(fill::Group::p4, {{1, 0}, {std::cos(1.0), std::sin(1.0)}}), InvalidInput);
  EXPECT_THROW(fill::group_lattice(fill::Group::p6, {{1, 0}, {0, 1}}), InvalidInput);
  EXPECT_THROW(fill::fill_wallpaper(fill::Group::p3, {{1, 0}, {0, 1}}, fill::circle_motif()), InvalidInput);
  try {
    fill::group_lattice(fill::Group::p31m, {{1, 0}, {0, 1}});
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("p31m"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("hexagonal"), std::string::npos);
  }
  // A hexagonal lattice at 60 degrees is the same lattice as at 120.
  const fill::Lattice l = fill::group_lattice(fill::Group::p6, {{1, 0}, {0.5, std::sqrt(3.0) / 2}});
  EXPECT_NEAR(l.b.x, -0.5, 1e-15);
}

// The replicated pattern of 5 x 5 cells: every operation (plus the lattice vector that keeps the middle cell
// in place) maps each motif centred in the middle cell onto a motif of the pattern with the same area.
void expect_invariant(const fill::WallpaperFill& f) {
  const std::vector<Placement2> all = fill::replicate(f, 5, 5);
  const fill::Lattice& l = f.lattice;
  const double det = cross2(l.a, l.b);
  auto to_cell = [&](const Vec2d& p) { return Vec2d{cross2(p, l.b) / det, cross2(l.a, p) / det}; };
  // Sorted by x for matching.
  std::vector<Placement2> sorted = all;
  std::sort(sorted.begin(), sorted.end(), [](const Placement2& a, const Placement2& b) { return a.center_mm.x < b.center_mm.x; });
  const double tol = 1e-9 * (len(l.a) + len(l.b));
  size_t checked = 0;
  for (const fill::Affine2& op : fill::cell_operations(f.group)) {
    const Vec2d mid{2.5, 2.5};
    const Vec2d moved = apply_op(op, mid);
    const Vec2d shift{std::round(mid.x - moved.x), std::round(mid.y - moved.y)};
    for (const Placement2& p : all) {
      const Vec2d c = to_cell(p.center_mm);
      if (c.x < 2 || c.x >= 3 || c.y < 2 || c.y >= 3) continue;
      const Vec2d ic = apply_op(op, c) + shift;
      const Vec2d target = l.a * ic.x + l.b * ic.y;
      auto it = std::lower_bound(sorted.begin(), sorted.end(), target.x - tol,
                                 [](const Placement2& a, double x) { return a.center_mm.x < x; });
      bool found = false;
      for (; it != sorted.end() && it->center_mm.x <= target.x + tol && !found; ++it)
        found = len(it->center_mm - target) <= tol && std::fabs(it->area_mm2 - p.area_mm2) <= 1e-12 * p.area_mm2;
      EXPECT_TRUE(found) << "image of a motif at cell (" << c.x << ", " << c.y << ") missing";
      ++checked;
    }
  }
  EXPECT_GT(checked, 0u);
}

double law_check(const fill::WallpaperFill& f) {
  const std::vector<Vec2d> r = fill::fundamental_region_mm(f.group, f.lattice);
  double A = 0;
  for (size_t i = 0; i < r.size(); ++i) A += cross2(r[i], r[(i + 1) % r.size()]) / 2;
  const double cell = std::fabs(cross2(f.lattice.a, f.lattice.b));
  EXPECT_NEAR(A, cell / double(fill::cell_operations(f.group).size()), 1e-12 * cell);
  return A;
}

TEST(Fill, WallpaperRejectCircles) {
  for (fill::Group g : kGroups) {
    SCOPED_TRACE(fill::group_name(g));
    fill::FillOptions o;
    o.max_count = 25;
    o.gap_mm = 0.01;
    o.seed = 3;
    const fill::WallpaperFill f = fill::fill_wallpaper(g, valid_lattice(g), fill::circle_motif(), o, fill::BoundaryPolicy::kReject);
    EXPECT_EQ(f.fundamental.stop_reason, "max_count");
    EXPECT_EQ(f.fundamental.motifs.size(), 25u);
    expect_area_law(f.fundamental, law_check(f), o.c, o.N, 0);
    // Centres in the fundamental region.
    const std::vector<Vec2d> region = fill::fundamental_region_mm(g, f.lattice);
    for (const Placement2& p : f.fundamental.motifs) EXPECT_TRUE(inside(region, p.center_mm));
    expect_invariant(f);
    const std::vector<Placement2> all = fill::replicate(f, 3, 3);
    EXPECT_EQ(all.size(), 9 * fill::cell_operations(g).size() * f.fundamental.motifs.size());
    expect_separated(f.motif, all, o.gap_mm);
  }
}

TEST(Fill, WallpaperRejectPolygons) {
  // An asymmetric, non-convex motif turned at random: its mirror images are distinct shapes.
  const Motif2 flag = fill::polygon_motif({{0, 0}, {3, 0}, {3, 2}, {2, 1}, {1, 2.5}, {0, 1.5}});
  for (fill::Group g : kGroups) {
    SCOPED_TRACE(fill::group_name(g));
    fill::FillOptions o;
    o.max_count = 15;
    o.gap_mm = 0.01;
    o.random_rotation = true;
    const fill::WallpaperFill f = fill::fill_wallpaper(g, valid_lattice(g), flag, o, fill::BoundaryPolicy::kReject);
    EXPECT_EQ(f.fundamental.motifs.size(), 15u) << f.fundamental.stop_reason;
    expect_invariant(f);
    expect_separated(f.motif, fill::replicate(f, 3, 3), o.gap_mm);
  }
}

TEST(Fill, WallpaperP1CirclesAcrossCells) {
  // Large circles (N close to 1): many of them straddle the cell's border.
  fill::FillOptions o;
  o.N = 1.2;
  o.max_count = 60;
  const fill::WallpaperFill f = fill::fill_wallpaper(fill::Group::p1, {{1, 0}, {0, 1}}, fill::circle_motif(), o);
  ASSERT_EQ(f.fundamental.motifs.size(), 60u);
  const std::vector<Placement2> all = fill::replicate(f, 3, 3);
  int straddling = 0;
  for (const Placement2& p : f.fundamental.motifs) {
    const double r = p.scale / std::sqrt(kPi);
    straddling += p.center_mm.x < r || p.center_mm.x > 1 - r || p.center_mm.y < r || p.center_mm.y > 1 - r;
  }
  EXPECT_GT(straddling, 3);
  for (size_t i = 0; i < all.size(); ++i)
    for (size_t j = i + 1; j < all.size(); ++j)
      EXPECT_GE(len(all[i].center_mm - all[j].center_mm), (all[i].scale + all[j].scale) / std::sqrt(kPi) - 1e-12);
}

TEST(Fill, WallpaperAllowAndSnap) {
  fill::FillOptions o;
  o.max_count = 40;
  o.N = 1.5;
  const fill::Group g = fill::Group::p4m;
  const fill::Lattice l{{1, 0}, {0, 1}};
  // Allow: some motif crosses a mirror and overlaps its own image; the pattern is still invariant and motifs
  // do not overlap images of other motifs.
  const fill::WallpaperFill allow = fill::fill_wallpaper(g, l, fill::circle_motif(), o, fill::BoundaryPolicy::kAllow);
  EXPECT_EQ(allow.fundamental.motifs.size(), 40u);
  expect_invariant(allow);
  // The fundamental triangle (0, 0), (1/2, 0), (1/2, 1/2) is bounded by the mirrors y = 0, x = 1/2, x = y.
  int cut = 0;
  for (const Placement2& p : allow.fundamental.motifs) {
    const double r = p.scale / std::sqrt(kPi), x = p.center_mm.x, y = p.center_mm.y;
    cut += y < r || 0.5 - x < r || (x - y) / std::sqrt(2.0) < r;
  }
  EXPECT_GT(cut, 0);
  // Images of different motifs never overlap (replicate lists each motif's 8 x 9 images together).
  const std::vector<Placement2> images = fill::replicate(allow, 3, 3);
  ASSERT_EQ(images.size(), 40u * 72);
  for (size_t i = 0; i < images.size(); ++i)
    for (size_t j = i + 1; j < images.size(); ++j)
      if (i / 72 != j / 72) {
        ASSERT_GE(len(images[i].center_mm - images[j].center_mm), (images[i].scale + images[j].scale) / std::sqrt(kPi) - 1e-12);
      }
  // Snap: squares aligned on the mirrors and centred on the rotation points.
  const Motif2 square = fill::regular_polygon_motif(4);
  const fill::WallpaperFill snap = fill::fill_wallpaper(g, l, square, o, fill::BoundaryPolicy::kSnap);
  EXPECT_EQ(snap.fundamental.motifs.size(), 40u) << snap.fundamental.stop_reason;
  expect_area_law(snap.fundamental, law_check(snap), o.c, o.N, 1);
  int snapped = 0;
  for (const Placement2& p : snap.fundamental.motifs) snapped += p.stabilizer_order > 1;
  EXPECT_GT(snapped, 0);
  expect_invariant(snap);
  expect_separated(square, fill::replicate(snap, 3, 3), o.gap_mm);
  // A motif without mirrors is never snapped onto a mirror: cut by one, it is rejected.
  const Motif2 quad = fill::polygon_motif({{0, 0}, {3, 0}, {2.5, 2}, {0.3, 1.4}});
  const fill::WallpaperFill none = fill::fill_wallpaper(g, l, quad, o, fill::BoundaryPolicy::kSnap);
  for (const Placement2& p : none.fundamental.motifs) EXPECT_EQ(p.stabilizer_order, 1);
  expect_separated(quad, fill::replicate(none, 3, 3), o.gap_mm);
}

// ---- spheres ----

void check_spheres(const fill::SignedDistance3& sd, const Box3& box, double volume, const fill::FillOptions3& o) {
  const fill::FillResult3 r = fill::fill_spheres(sd, box, volume, o);
  SCOPED_TRACE(r.stop_reason);
  ASSERT_EQ(r.centers_mm.size(), o.max_count);
  ASSERT_EQ(r.radii_mm.size(), o.max_count);
  const double z = fill::hurwitz_zeta(o.c, o.N);
  for (size_t i = 0; i < r.centers_mm.size(); ++i) {
    const double v = volume / (z * std::pow(o.N + double(i), o.c));
    EXPECT_NEAR(4.0 / 3 * kPi * std::pow(r.radii_mm[i], 3), v, 1e-12 * v);
    EXPECT_LE(sd(r.centers_mm[i]), -(r.radii_mm[i] + o.boundary_gap_mm) + 1e-12);
  }
  for (size_t i = 0; i < r.centers_mm.size(); ++i)
    for (size_t j = i + 1; j < r.centers_mm.size(); ++j)
      EXPECT_GE(norm(r.centers_mm[i] - r.centers_mm[j]), r.radii_mm[i] + r.radii_mm[j] + o.gap_mm - 1e-12);
  double f = 0;
  for (size_t i = 0; i < r.centers_mm.size(); ++i) f += 1 / (z * std::pow(o.N + double(i), o.c));
  EXPECT_EQ(r.fill_fraction, f);
}

TEST(Fill, Spheres) {
  // In 3D a large first sphere in the middle leaves no room for the second one (in a cube of side 4, with
  // c = 1.2 the first two have radii 1.13 and 0.96): c close to 1 keeps the first ones small.
  fill::FillOptions3 o;
  o.max_count = 500;
  o.c = 1.1;
  o.gap_mm = 0.02;
  o.boundary_gap_mm = 0.05;
  Box3 box;
  box.expand(Vec3d{0, 0, 0});
  box.expand(Vec3d{5, 4, 3});
  // The exact distance of the box, checked at a few points.
  const fill::SignedDistance3 d = fill::box_region_distance(box);
  EXPECT_DOUBLE_EQ(d({2, 2, 1}), -1);
  EXPECT_DOUBLE_EQ(d({6, 2, 1.5}), 1);
  EXPECT_DOUBLE_EQ(d({6, 5, 1.5}), std::sqrt(2.0));
  check_spheres(d, box, 60, o);
  o.seed = 4;
  Box3 ball_box;
  ball_box.expand(Vec3d{-2, -2, -2});
  ball_box.expand(Vec3d{2, 2, 2});
  check_spheres(fill::sphere_region_distance({0, 0, 0}, 2), ball_box, 4.0 / 3 * kPi * 8, o);
  fill::FillOptions3 tight;
  tight.max_trials = 3;
  tight.N = 1.01;
  tight.c = 3;
  EXPECT_EQ(fill::fill_spheres(d, box, 60, tight).stop_reason, "max_trials: sphere 0 could not be placed in 3 trials");
  EXPECT_THROW(fill::fill_spheres(d, box, 0, o), InvalidInput);
  EXPECT_THROW(fill::sphere_region_distance({0, 0, 0}, -1), InvalidInput);
}

}  // namespace
}  // namespace lacuna

namespace lacuna {
namespace {

TEST(Fill, WallpaperSnapEveryGroup) {
  // Circles have every symmetry, so under snap any motif meeting a mirror or a rotation centre is
  // moved onto it. In every group the result is invariant, no two motifs (images included)
  // overlap, and the areas follow the law with the stabilizer factor.
  fill::FillOptions o;
  o.max_count = 25;
  o.N = 1.5;
  o.gap_mm = 0.01;
  int snapped_groups = 0;
  for (int gi = 0; gi < 17; ++gi) {
    const fill::Group g = fill::Group(gi);
    SCOPED_TRACE(fill::group_name(g));
    const fill::WallpaperFill snap = fill::fill_wallpaper(g, valid_lattice(g), fill::circle_motif(), o, fill::BoundaryPolicy::kSnap);
    ASSERT_GT(snap.fundamental.motifs.size(), 5u) << snap.fundamental.stop_reason;
    expect_area_law(snap.fundamental, law_check(snap), o.c, o.N, 1);
    expect_invariant(snap);
    expect_separated(snap.motif, fill::replicate(snap, 3, 3), o.gap_mm);
    int snapped = 0;
    for (const Placement2& p : snap.fundamental.motifs) snapped += p.stabilizer_order > 1;
    snapped_groups += snapped > 0;
    if (g == fill::Group::p1) {
      EXPECT_EQ(snapped, 0);  // p1 has nothing to snap onto
    }
  }
  EXPECT_GE(snapped_groups, 8);  // most groups met a mirror or a centre in 25 motifs
}

// What the area law leaves uncovered is a fractal of dimension 2 / c (the spec): box counting of the
// uncovered set of 8000 circles (c = 1.3, N = 2) in a 100 mm square, at box sides 100/32 .. 100/512 mm,
// within 0.1 of it. (c = 1.5 is not tested: its placement stalls long before the boxes resolve the
// fractal; README, Benchmarks.)
TEST(Fill, UncoveredSetHasDimensionTwoOverC) {
  fill::FillOptions f;
  f.c = 1.3;
  f.N = 2;
  f.max_count = 8000;
  f.max_trials = 200000;
  f.seed = 3;
  const fill::FillResult2 r = fill::fill_region(fill::rectangle_region({0, 0}, {100, 100}), fill::circle_motif(), f);
  ASSERT_EQ(r.motifs.size(), 8000u) << r.stop_reason;
  const fill::UncoveredBoxCount boxes = fill::uncovered_box_count(r.motifs, 100, 5, 9);
  EXPECT_NEAR(boxes.dimension, 2 / f.c, 0.1);
  // The counts grow as the boxes shrink, each level at most 4 times the one before.
  for (size_t i = 1; i < boxes.boxes.size(); ++i) {
    EXPECT_GT(boxes.boxes[i], boxes.boxes[i - 1]);
    EXPECT_LE(boxes.boxes[i], 4 * boxes.boxes[i - 1]);
  }
}

TEST(Fill, SvgPathsOfStraightSegments) {
  // Absolute and relative moves and lines, horizontal and vertical lines, implicit line-tos, exponents.
  const std::vector<Vec2d> p = fill::svg_path_points("M1,2 L3 2 h2 v1e0 l-1,1 H0.5 V 3 z", "square.svg");
  const std::vector<Vec2d> expected{{1, 2}, {3, 2}, {5, 2}, {5, 3}, {4, 4}, {0.5, 4}, {0.5, 3}};
  ASSERT_EQ(p.size(), expected.size());
  for (size_t i = 0; i < p.size(); ++i) EXPECT_TRUE(p[i].x == expected[i].x && p[i].y == expected[i].y) << i;
  const std::vector<Vec2d> q = fill::svg_path_points("m 1 1 2 0 0 2 -2 0 Z", "q");
  ASSERT_EQ(q.size(), 4u);
  EXPECT_TRUE(q[2].x == 3 && q[2].y == 3);
  // A closing point equal to the first is the same corner.
  EXPECT_EQ(fill::svg_path_points("M0 0 L1 0 L0 1 L0 0 Z", "t").size(), 3u);
  for (const char* bad : {"M0 0 C1 1 2 2 3 3 Z", "M0 0 L1 0 L0 1 Z M5 5 L6 5 L5 6 Z", "L1 0 2 2", "M0 0 L1 x", "", "M0 0 A 1 1 0 0 1 2 2"})
    EXPECT_THROW(fill::svg_path_points(bad, "bad.svg"), InvalidInput) << bad;
  try {
    fill::svg_path_points("M0 0 Q1 1 2 0 Z", "curvy.svg");
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("curvy.svg"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'Q'"), std::string::npos) << e.what();
  }
}

TEST(Fill, MotifFilesKeepTheirSymmetry) {
  // A regular five-pointed star written to 17 digits: rotation order 5 and five mirrors, from an SVG path
  // (y down, so the star is flipped, which keeps its symmetry) and from a JSON list.
  test::TempDir dir;
  std::string d = "M", json = "[";
  char buf[96];
  for (int k = 0; k < 10; ++k) {
    const double r = k % 2 ? 0.4 : 1, a = kPi / 2 + k * kPi / 5;
    std::snprintf(buf, sizeof buf, "%s%.17g,%.17g", k ? " " : "", r * std::cos(a), r * std::sin(a));
    d += buf;
    std::snprintf(buf, sizeof buf, "%s[%.17g, %.17g]", k ? ", " : "", r * std::cos(a), r * std::sin(a));
    json += buf;
  }
  test::write_file(dir / "star.svg", "<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\">\n  <path id=\"star\" d=\"" + d + " Z\"/>\n</svg>\n");
  test::write_file(dir / "star.json", json + "]");
  test::write_file(dir / "star_object.json", "{\"polygon\": " + json + "]}");
  for (const char* name : {"star.svg", "star.json", "star_object.json"}) {
    const std::vector<Vec2d> outline = fill::read_motif_outline((dir / name).string());
    ASSERT_EQ(outline.size(), 10u) << name;
    const Motif2 m = fill::polygon_motif(outline);
    EXPECT_EQ(m.rotation_order, 5) << name;
    EXPECT_EQ(m.mirror_angles_rad.size(), 5u) << name;
    EXPECT_FALSE(m.convex) << name;
  }
  // SVG's y axis points down: the first point (0, 1) reads as (0, -1).
  EXPECT_NEAR(fill::read_motif_outline((dir / "star.svg").string())[0].y, -1, 1e-15);
  test::write_file(dir / "flat.svg", "<svg><path d=\"M0 0 C1 1 2 2 0 1 Z\"/></svg>");
  test::write_file(dir / "none.svg", "<svg><rect width=\"1\" height=\"1\"/></svg>");
  test::write_file(dir / "bad.json", "[[0, 0], [1, 0], [1]]");
  for (const char* name : {"flat.svg", "none.svg", "bad.json", "motif.png"})
    EXPECT_THROW(fill::read_motif_outline((dir / name).string()), InvalidInput) << name;
  EXPECT_THROW(fill::read_motif_outline((dir / "missing.svg").string()), IoError);
}

TEST(Fill, MotifColoursBySizeOrbitAndChance) {
  // p1 circles without snapping: motif i has area A / (zeta(c, N) (N + i)^c), so its size class (octaves
  // below the first motif's area) is floor(c log2((N + i) / N)).
  fill::FillOptions o;
  o.c = 1.3;
  o.N = 2;
  o.max_count = 60;
  o.seed = 5;
  const fill::WallpaperFill f = fill::fill_wallpaper(fill::Group::p4, {{10, 0}, {0, 10}}, fill::circle_motif(), o);
  const std::vector<Placement2>& motifs = f.fundamental.motifs;
  ASSERT_GT(motifs.size(), 20u);
  const std::vector<int> size = fill::motif_colors(f.fundamental, fill::Coloring::kSize, 64, 1);
  for (size_t i = 0; i < motifs.size(); ++i)
    EXPECT_EQ(size[i], int(std::floor(o.c * std::log2((o.N + double(i)) / o.N) + 1e-12))) << i;
  const std::vector<int> size3 = fill::motif_colors(f.fundamental, fill::Coloring::kSize, 3, 1);
  for (size_t i = 0; i < motifs.size(); ++i) EXPECT_EQ(size3[i], size[i] % 3) << i;
  const std::vector<int> orbit = fill::motif_colors(f.fundamental, fill::Coloring::kOrbit, 4, 1);
  for (size_t i = 0; i < motifs.size(); ++i) EXPECT_EQ(orbit[i], int(i % 4)) << i;
  const std::vector<int> random = fill::motif_colors(f.fundamental, fill::Coloring::kRandom, 4, 9);
  EXPECT_EQ(random, fill::motif_colors(f.fundamental, fill::Coloring::kRandom, 4, 9));
  std::set<int> used(random.begin(), random.end());
  EXPECT_EQ(used, (std::set<int>{0, 1, 2, 3}));  // 4 colours over more than 20 motifs
  EXPECT_THROW(fill::motif_colors(f.fundamental, fill::Coloring::kOrbit, 0, 1), InvalidInput);
  // The picture: every image of a motif in its motif's colour, |p4| = 4 images per motif and cell.
  const std::vector<std::string> palette{"#000001", "#000002", "#000003", "#000004"};
  std::vector<std::string> fills;
  for (int c : orbit) fills.push_back(palette[size_t(c)]);
  const std::string svg = fill::wallpaper_svg(f, 2, fills);
  std::vector<uint32_t> orbits;
  const std::vector<Placement2> all = fill::replicate(f, 2, 2, &orbits);
  ASSERT_EQ(orbits.size(), all.size());
  EXPECT_EQ(all.size(), motifs.size() * 4 * 4);
  for (int c = 0; c < 4; ++c) {
    size_t drawn = 0, expected = 0;
    const std::string tag = "fill=\"" + palette[size_t(c)] + "\"";
    for (size_t at = svg.find(tag); at != std::string::npos; at = svg.find(tag, at + 1)) ++drawn;
    for (uint32_t m : orbits) expected += orbit[m] == c;
    EXPECT_EQ(drawn, expected) << c;
    EXPECT_GT(drawn, 0u);
  }
  EXPECT_THROW(fill::wallpaper_svg(f, 2, {"#000000"}), InvalidInput);
  EXPECT_EQ(fill::parse_palette(" #1B9E77, #d95f02"), (std::vector<std::string>{"#1b9e77", "#d95f02"}));
  for (const char* bad : {"", "#12345", "#12345g", "1b9e77", "#1b9e77,,#d95f02"})
    EXPECT_THROW(fill::parse_palette(bad), InvalidInput) << bad;
}

}  // namespace
}  // namespace lacuna
