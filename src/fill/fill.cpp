#include "fill/fill.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include "errors.h"
#include "fill/shape2.h"

namespace lacuna {
namespace fill {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// B_2j / (2j)! for j = 1 .. 13: the coefficients of the Euler-Maclaurin corrections.
constexpr double kBernoulliOverFactorial[] = {
    1.0 / 6 / 2,
    -1.0 / 30 / 24,
    1.0 / 42 / 720,
    -1.0 / 30 / 40320,
    5.0 / 66 / 3628800,
    -691.0 / 2730 / 479001600,
    7.0 / 6 / 87178291200.0,
    -3617.0 / 510 / 20922789888000.0,
    43867.0 / 798 / 6402373705728000.0,
    -174611.0 / 330 / 2432902008176640000.0,
    854513.0 / 138 / 1124000727777607680000.0,
    -236364091.0 / 2730 / 620448401733239439360000.0,
    8553103.0 / 6 / 403291461126605635584000000.0,
};

void check_finite(const std::vector<Vec2d>& points, const char* what) {
  for (const Vec2d& p : points)
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) throw InvalidInput(std::string(what) + " has a non-finite point");
}


// Drops repeated points and points on the straight line through their neighbours (not spikes, which the
// simplicity test rejects), makes the polygon counter-clockwise and checks that it is simple.
std::vector<Vec2d> clean_simple_polygon(const std::vector<Vec2d>& points, const char* what) {
  check_finite(points, what);
  double size = 0;
  for (const Vec2d& p : points) size = std::max({size, std::fabs(p.x), std::fabs(p.y)});
  const double eps = 1e-12 * size;
  std::vector<Vec2d> p;
  for (const Vec2d& q : points)
    if (p.empty() || detail::length2(q - p.back()) > eps) p.push_back(q);
  while (p.size() > 1 && detail::length2(p.front() - p.back()) <= eps) p.pop_back();
  for (bool changed = true; changed && p.size() >= 3;) {
    changed = false;
    for (size_t i = 0; i < p.size() && p.size() >= 3; ++i) {
      const Vec2d a = p[(i + p.size() - 1) % p.size()], b = p[i], c = p[(i + 1) % p.size()];
      const Vec2d u = b - a, v = c - b;
      if (std::fabs(cross2(u, v)) <= 1e-12 * detail::length2(u) * detail::length2(v) &&
          detail::dot2(u, v) > 0) {
        p.erase(p.begin() + long(i));
        changed = true;
      }
    }
  }
  if (p.size() < 3) throw InvalidInput(std::string(what) + " needs at least 3 distinct, non-collinear points");
  const double a = signed_area(p);
  if (!(std::fabs(a) > 1e-24 * size * size)) throw InvalidInput(std::string(what) + " has zero area");
  if (a < 0) std::reverse(p.begin(), p.end());
  const size_t n = p.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) {
        // Adjacent edges share a vertex; they overlap only when the outline doubles back.
        const size_t shared = j == i + 1 ? j : i;
        const Vec2d prev = p[(shared + n - 1) % n], next = p[(shared + 1) % n], s = p[shared];
        if (std::fabs(cross2(s - prev, next - s)) <= 1e-12 * detail::length2(s - prev) * detail::length2(next - s) &&
            detail::dot2(s - prev, next - s) < 0)
          throw InvalidInput(std::string(what) + " doubles back on itself at point " + std::to_string(shared));
        continue;
      }
      if (segments_intersect(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]))
        throw InvalidInput(std::string(what) + " is not simple: edges " + std::to_string(i) + " and " +
                           std::to_string(j) + " meet");
    }
  return p;
}

Vec2d centroid(const std::vector<Vec2d>& p) {
  double a = 0, x = 0, y = 0;
  for (size_t i = 0, n = p.size(); i < n; ++i) {
    const Vec2d u = p[i], v = p[(i + 1) % n];
    const double w = cross2(u, v);
    a += w;
    x += (u.x + v.x) * w;
    y += (u.y + v.y) * w;
  }
  return {x / (3 * a), y / (3 * a)};
}

// A point strictly inside: the centroid when it is, else the middle of the widest inside interval on a
// horizontal line through the centroid (nudged off the vertices' heights).
Vec2d interior_point(const std::vector<Vec2d>& p) {
  const Vec2d c = centroid(p);
  if (detail::point_in_polygon(p, c) && detail::outline_distance(p, c) > 1e-9) return c;
  double ymin = HUGE_VAL, ymax = -HUGE_VAL;
  for (const Vec2d& q : p) ymin = std::min(ymin, q.y), ymax = std::max(ymax, q.y);
  Vec2d best = c;
  double best_width = -1;
  for (int attempt = 0; attempt < 16; ++attempt) {
    const double y = ymin + (ymax - ymin) * (0.5 + 0.03 * (attempt % 2 ? attempt : -attempt) + 0.0012345);
    std::vector<double> xs;
    for (size_t i = 0, n = p.size(); i < n; ++i) {
      const Vec2d a = p[i], b = p[(i + 1) % n];
      if ((a.y > y) != (b.y > y)) xs.push_back(a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x));
    }
    std::sort(xs.begin(), xs.end());
    for (size_t i = 0; i + 1 < xs.size(); i += 2)
      if (xs[i + 1] - xs[i] > best_width) best_width = xs[i + 1] - xs[i], best = {(xs[i] + xs[i + 1]) / 2, y};
    if (best_width > 0) break;
  }
  return best;
}

Vec2d rotate(const Vec2d& v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * v.x - s * v.y, s * v.x + c * v.y};
}

// Whether the map v -> image(v) sends vertex i onto vertex (k + step * i) mod n for one k, to tol.
template <class Map>
bool maps_outline(const std::vector<Vec2d>& p, Map image, int step, double tol) {
  const long n = long(p.size());
  const Vec2d first = image(p[0]);
  for (long k = 0; k < n; ++k) {
    if (detail::length2(first - p[size_t(k)]) > tol) continue;
    bool all = true;
    for (long i = 1; i < n && all; ++i)
      all = detail::length2(image(p[size_t(i)]) - p[size_t((((k + step * i) % n) + n) % n)]) <= tol;
    if (all) return true;
  }
  return false;
}

void detect_symmetry(Motif2& m) {
  const std::vector<Vec2d>& p = m.outline;
  const int n = int(p.size());
  const double tol = 1e-9 * m.bounding_radius;
  // The rotations form a cyclic group acting freely on the vertices: its order divides n.
  m.rotation_order = 1;
  for (int order = n; order >= 2; --order) {
    if (n % order) continue;
    const double angle = 2 * kPi / order;
    if (maps_outline(p, [&](const Vec2d& v) { return rotate(v, angle); }, 1, tol)) {
      m.rotation_order = order;
      break;
    }
  }
  // A mirror line through the centroid passes through a vertex or an edge midpoint.
  std::vector<double> candidates;
  for (int i = 0; i < n; ++i) {
    const Vec2d mid = (p[size_t(i)] + p[size_t((i + 1) % n)]) * 0.5;
    for (const Vec2d& q : {p[size_t(i)], mid})
      if (detail::length2(q) > tol) {
        double a = std::atan2(q.y, q.x);
        a = std::fmod(a + 2 * kPi, kPi);
        candidates.push_back(a);
      }
  }
  std::sort(candidates.begin(), candidates.end());
  m.mirror_angles_rad.clear();
  for (double a : candidates) {
    if (!m.mirror_angles_rad.empty() && a - m.mirror_angles_rad.back() < 1e-9) continue;
    if (!m.mirror_angles_rad.empty() && kPi - a + m.mirror_angles_rad.front() < 1e-9) continue;
    const Vec2d d{std::cos(a), std::sin(a)};
    auto reflect = [&](const Vec2d& v) { return d * (2 * detail::dot2(v, d)) - v; };
    if (maps_outline(p, reflect, -1, tol)) m.mirror_angles_rad.push_back(a);
  }
}


}  // namespace

// ---- shapes (fill/shape2.h) ----
namespace detail {

Shape2 place(const Motif2& motif, const Placement2& pl) {
  Shape2 s;
  s.center = pl.center_mm;
  s.radius = pl.scale * motif.bounding_radius;
  s.circle = motif.kind == Motif2::Kind::kCircle;
  s.convex = motif.convex;
  const double c = std::cos(pl.angle_rad) * pl.scale, sn = std::sin(pl.angle_rad) * pl.scale;
  auto map = [&](const Vec2d& v) {
    const double y = pl.mirrored ? -v.y : v.y;
    return Vec2d{pl.center_mm.x + c * v.x - sn * y, pl.center_mm.y + sn * v.x + c * y};
  };
  s.interior = map(motif.interior_point);
  s.points.reserve(motif.outline.size());
  for (const Vec2d& v : motif.outline) s.points.push_back(map(v));
  if (pl.mirrored) std::reverse(s.points.begin(), s.points.end());
  return s;
}

bool point_in_polygon(const std::vector<Vec2d>& poly, const Vec2d& p) {
  bool inside = false;
  for (size_t i = 0, n = poly.size(), j = n - 1; i < n; j = i++) {
    const Vec2d a = poly[i], b = poly[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x)) inside = !inside;
  }
  return inside;
}

double outline_distance(const std::vector<Vec2d>& poly, const Vec2d& p) {
  double d = HUGE_VAL;
  for (size_t i = 0, n = poly.size(); i < n; ++i) d = std::min(d, point_segment_distance(p, poly[i], poly[(i + 1) % n]));
  return d;
}

bool outlines_intersect(const std::vector<Vec2d>& a, const std::vector<Vec2d>& b) {
  for (size_t i = 0, n = a.size(); i < n; ++i)
    for (size_t j = 0, m = b.size(); j < m; ++j)
      if (segments_intersect(a[i], a[(i + 1) % n], b[j], b[(j + 1) % m])) return true;
  return false;
}

double vertex_outline_distance(const std::vector<Vec2d>& a, const std::vector<Vec2d>& b) {
  double d = HUGE_VAL;
  for (const Vec2d& p : a) d = std::min(d, outline_distance(b, p));
  for (const Vec2d& p : b) d = std::min(d, outline_distance(a, p));
  return d;
}

namespace {

// Separating axes of two convex polygons: the largest separation of their projections on an edge normal.
// It is >= 0 exactly when they do not overlap, and a lower bound on their distance.
double axis_separation(const std::vector<Vec2d>& a, const std::vector<Vec2d>& b) {
  double best = -HUGE_VAL;
  for (const auto* p : {&a, &b})
    for (size_t i = 0, n = p->size(); i < n; ++i) {
      const Vec2d e = (*p)[(i + 1) % n] - (*p)[i];
      const double l = length2(e);
      if (l == 0) continue;
      const Vec2d normal{e.y / l, -e.x / l};
      double amin = HUGE_VAL, amax = -HUGE_VAL, bmin = HUGE_VAL, bmax = -HUGE_VAL;
      for (const Vec2d& q : a) amin = std::min(amin, dot2(q, normal)), amax = std::max(amax, dot2(q, normal));
      for (const Vec2d& q : b) bmin = std::min(bmin, dot2(q, normal)), bmax = std::max(bmax, dot2(q, normal));
      best = std::max(best, std::max(bmin - amax, amin - bmax));
    }
  return best;
}

}  // namespace

bool overlap(const Shape2& a, const Shape2& b, double gap) {
  const double d = length2(a.center - b.center);
  if (d >= a.radius + b.radius + gap) return false;
  if (a.circle && b.circle) return true;
  if (a.circle || b.circle) {
    const Shape2& c = a.circle ? a : b;
    const Shape2& p = a.circle ? b : a;
    return point_in_polygon(p.points, c.center) || outline_distance(p.points, c.center) < c.radius + gap;
  }
  if (a.convex && b.convex) {
    const double separation = axis_separation(a.points, b.points);
    if (separation >= gap) return false;
    if (separation <= 0) return true;
    // Apart, but closer than the gap along every axis: the exact distance decides (corners facing).
    return vertex_outline_distance(a.points, b.points) < gap;
  }
  // Outlines that do not meet bound disjoint polygons or one inside the other.
  if (outlines_intersect(a.points, b.points)) return true;
  if (point_in_polygon(b.points, a.interior) || point_in_polygon(a.points, b.interior)) return true;
  return gap > 0 && vertex_outline_distance(a.points, b.points) < gap;
}

void check_law(double c, double N, double gap, double boundary_gap, size_t trials, size_t count) {
  if (count > kMaxFillCount) throw InvalidInput("fill: count must be at most 10 000 000, got " + std::to_string(count));
  if (!(std::isfinite(c) && c > 1)) throw InvalidInput("fill: the exponent c must be > 1, got " + number(c));
  if (!(std::isfinite(N) && N > 1)) throw InvalidInput("fill: the offset N must be > 1, got " + number(N));
  if (!(std::isfinite(gap) && gap >= 0)) throw InvalidInput("fill: gap_mm must be >= 0, got " + number(gap));
  if (!(std::isfinite(boundary_gap) && boundary_gap >= 0))
    throw InvalidInput("fill: boundary_gap_mm must be >= 0, got " + number(boundary_gap));
  if (trials == 0) throw InvalidInput("fill: max_trials must be at least 1");
}

std::string trials_reason(const char* what, size_t i, size_t trials) {
  return "max_trials: " + std::string(what) + " " + std::to_string(i) + " could not be placed in " +
         std::to_string(trials) + " trials";
}

}  // namespace detail

double hurwitz_zeta(double s, double q) {
  if (!(std::isfinite(s) && s > 1)) throw InvalidInput("hurwitz_zeta: s must be a finite number > 1, got " + number(s));
  if (!(std::isfinite(q) && q > 0)) throw InvalidInput("hurwitz_zeta: q must be a finite number > 0, got " + number(q));
  // Euler-Maclaurin: the first M terms directly (smallest first), then for x = q + M
  //   sum_{k >= 0} (x + k)^-s = x^(1-s) / (s-1) + x^-s / 2 + sum_j B_2j / (2j)! s (s+1) ... (s+2j-2) x^(-s-2j+1) + R.
  // Successive corrections shrink by about ((s + 2j) / (2 pi x))^2, so with x >= 16 + s the 13 of them leave R
  // far below double precision.
  const int M = 16 + int(std::min(s, 1000.0));
  double sum = 0;
  for (int k = M - 1; k >= 0; --k) sum += std::pow(q + k, -s);
  const double x = q + M;
  double tail = std::pow(x, 1 - s) / (s - 1) + std::pow(x, -s) / 2;
  double factor = s * std::pow(x, -s - 1);  // s (s+1) ... (s+2j-2) x^(-s-2j+1)
  for (int j = 1; j <= 13; ++j) {
    const double term = kBernoulliOverFactorial[j - 1] * factor;
    tail += term;
    if (std::fabs(term) < 1e-18 * tail) break;
    factor *= (s + 2 * j - 1) * (s + 2 * j) / (x * x);
  }
  return sum + tail;
}

Motif2 circle_motif() { return Motif2{}; }

Motif2 regular_polygon_motif(int n) {
  if (n < 3 || n > 100000) throw InvalidInput("a regular polygon needs 3 to 100000 sides, got " + std::to_string(n));
  // Area n/2 R^2 sin(2 pi / n) = 1.
  const double r = std::sqrt(2 / (n * std::sin(2 * kPi / n)));
  std::vector<Vec2d> p;
  for (int k = 0; k < n; ++k) p.push_back({r * std::cos(2 * kPi * k / n), r * std::sin(2 * kPi * k / n)});
  Motif2 m = polygon_motif(p);
  // Exact values rather than the detected ones (the same to 1e-9).
  m.rotation_order = n;
  m.mirror_angles_rad.clear();
  for (int k = 0; k < n; ++k) m.mirror_angles_rad.push_back(kPi * k / n);
  return m;
}

Motif2 polygon_motif(const std::vector<Vec2d>& points) {
  std::vector<Vec2d> p = clean_simple_polygon(points, "a motif polygon");
  const Vec2d c = centroid(p);
  const double scale = 1 / std::sqrt(signed_area(p));
  Motif2 m;
  m.kind = Motif2::Kind::kPolygon;
  m.bounding_radius = 0;
  for (Vec2d& q : p) {
    q = (q - c) * scale;
    m.bounding_radius = std::max(m.bounding_radius, detail::length2(q));
  }
  m.outline = p;
  m.convex = true;
  for (size_t i = 0, n = p.size(); i < n; ++i)
    if (cross2(p[(i + 1) % n] - p[i], p[(i + 2) % n] - p[(i + 1) % n]) < 0) m.convex = false;
  m.interior_point = interior_point(p);
  detect_symmetry(m);
  return m;
}

std::vector<Vec2d> placed_outline(const Motif2& motif, const Placement2& placement) {
  if (motif.kind == Motif2::Kind::kCircle) {
    const double r = placement.scale * motif.bounding_radius;
    std::vector<Vec2d> out;
    for (int k = 0; k < 64; ++k)
      out.push_back(placement.center_mm + Vec2d{r * std::cos(2 * kPi * k / 64), r * std::sin(2 * kPi * k / 64)});
    return out;
  }
  return detail::place(motif, placement).points;
}

FillRegion2 rectangle_region(const Vec2d& min_mm, const Vec2d& max_mm) {
  check_finite({min_mm, max_mm}, "a fill rectangle");
  if (!(min_mm.x < max_mm.x && min_mm.y < max_mm.y)) throw InvalidInput("a fill rectangle needs min < max on both axes");
  FillRegion2 r;
  r.kind = FillRegion2::Kind::kRectangle;
  r.min_mm = min_mm;
  r.max_mm = max_mm;
  return r;
}

FillRegion2 disk_region(const Vec2d& center_mm, double radius_mm) {
  check_finite({center_mm}, "a fill disk");
  if (!(std::isfinite(radius_mm) && radius_mm > 0)) throw InvalidInput("a fill disk needs a radius > 0, got " + number(radius_mm));
  FillRegion2 r;
  r.kind = FillRegion2::Kind::kDisk;
  r.center_mm = center_mm;
  r.radius_mm = radius_mm;
  return r;
}

FillRegion2 polygon_region(const std::vector<Vec2d>& points_mm) {
  FillRegion2 r;
  r.kind = FillRegion2::Kind::kPolygon;
  r.polygon_mm = clean_simple_polygon(points_mm, "a fill polygon");
  return r;
}

double area(const FillRegion2& region) {
  switch (region.kind) {
    case FillRegion2::Kind::kRectangle:
      return (region.max_mm.x - region.min_mm.x) * (region.max_mm.y - region.min_mm.y);
    case FillRegion2::Kind::kDisk:
      return kPi * region.radius_mm * region.radius_mm;
    case FillRegion2::Kind::kPolygon:
      return std::fabs(signed_area(region.polygon_mm));
  }
  return 0;
}

namespace {

bool contains_shape(const FillRegion2& region, const detail::Shape2& s, double g) {
  switch (region.kind) {
    case FillRegion2::Kind::kRectangle: {
      // The rectangle shrunk by g is convex: a polygon lies in it when its vertices do.
      const Vec2d lo = region.min_mm + Vec2d{g, g}, hi = region.max_mm - Vec2d{g, g};
      if (s.circle)
        return s.center.x - s.radius >= lo.x && s.center.x + s.radius <= hi.x && s.center.y - s.radius >= lo.y &&
               s.center.y + s.radius <= hi.y;
      for (const Vec2d& p : s.points)
        if (p.x < lo.x || p.x > hi.x || p.y < lo.y || p.y > hi.y) return false;
      return true;
    }
    case FillRegion2::Kind::kDisk: {
      const double r = region.radius_mm - g;
      if (s.circle) return detail::length2(s.center - region.center_mm) + s.radius <= r;
      for (const Vec2d& p : s.points)
        if (detail::length2(p - region.center_mm) > r) return false;
      return true;
    }
    case FillRegion2::Kind::kPolygon: {
      const std::vector<Vec2d>& poly = region.polygon_mm;
      if (s.circle) return detail::point_in_polygon(poly, s.center) && detail::outline_distance(poly, s.center) >= s.radius + g;
      // Inside when the outlines do not meet, one point of the motif is inside and the region is not inside
      // the motif; then the distance between the outlines is the clearance.
      if (!detail::point_in_polygon(poly, s.interior) || detail::point_in_polygon(s.points, poly[0])) return false;
      if (detail::outlines_intersect(s.points, poly)) return false;
      return g <= 0 || detail::vertex_outline_distance(s.points, poly) >= g;
    }
  }
  return false;
}

// The bounding box that trial centres are drawn from.
void region_box(const FillRegion2& region, Vec2d& lo, Vec2d& hi) {
  switch (region.kind) {
    case FillRegion2::Kind::kRectangle:
      lo = region.min_mm, hi = region.max_mm;
      return;
    case FillRegion2::Kind::kDisk:
      lo = region.center_mm - Vec2d{region.radius_mm, region.radius_mm};
      hi = region.center_mm + Vec2d{region.radius_mm, region.radius_mm};
      return;
    case FillRegion2::Kind::kPolygon:
      lo = {HUGE_VAL, HUGE_VAL}, hi = {-HUGE_VAL, -HUGE_VAL};
      for (const Vec2d& p : region.polygon_mm)
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)}, hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
      return;
  }
}

}  // namespace

bool contains(const FillRegion2& region, const Motif2& motif, const Placement2& placement, double clearance_mm) {
  return contains_shape(region, detail::place(motif, placement), clearance_mm);
}

FillResult2 fill_region(const FillRegion2& region, const Motif2& motif, const FillOptions& options) {
  detail::check_law(options.c, options.N, options.gap_mm, options.boundary_gap_mm, options.max_trials, options.max_count);
  const double A = area(region);
  Vec2d lo, hi;
  region_box(region, lo, hi);
  const bool turn = options.random_rotation && motif.kind == Motif2::Kind::kPolygon;
  const double turn_range = 2 * kPi / std::max(1, motif.rotation_order);
  Random random(options.seed);
  detail::GridIndex<2> index;
  std::vector<detail::Shape2> shapes;
  FillResult2 result;
  result.fill_fraction = detail::place_by_rule(
      A, options.c, options.N, options.max_count, options.min_area_mm2, "min_area", options.max_trials, "motif",
      result.stop_reason, [&](size_t, double area_i) {
        Placement2 pl;
        pl.area_mm2 = area_i;
        pl.scale = std::sqrt(area_i);
        pl.center_mm = {lo.x + (hi.x - lo.x) * random.uniform(), lo.y + (hi.y - lo.y) * random.uniform()};
        if (turn) pl.angle_rad = turn_range * random.uniform();
        detail::Shape2 s = detail::place(motif, pl);
        if (!contains_shape(region, s, options.boundary_gap_mm)) return false;
        if (index.any({s.center.x, s.center.y}, s.radius + options.gap_mm,
                      [&](int id) { return detail::overlap(s, shapes[size_t(id)], options.gap_mm); }))
          return false;
        index.insert(int(shapes.size()), {s.center.x, s.center.y}, s.radius);
        shapes.push_back(std::move(s));
        result.motifs.push_back(pl);
        return true;
      });
  return result;
}

FillResult3 fill_spheres(const SignedDistance3& signed_distance_mm, const Box3& box, double volume_mm3,
                         const FillOptions3& options) {
  detail::check_law(options.c, options.N, options.gap_mm, options.boundary_gap_mm, options.max_trials, options.max_count);
  if (!signed_distance_mm) throw InvalidInput("fill_spheres needs a signed distance function");
  if (box.empty() || !is_finite(box.min) || !is_finite(box.max)) throw InvalidInput("fill_spheres needs a finite, non-empty box");
  if (!(std::isfinite(volume_mm3) && volume_mm3 > 0))
    throw InvalidInput("fill_spheres needs a region volume > 0, got " + number(volume_mm3));
  Random random(options.seed);
  detail::GridIndex<3> index;
  FillResult3 result;
  result.fill_fraction = detail::place_by_rule(
      volume_mm3, options.c, options.N, options.max_count, options.min_volume_mm3, "min_volume", options.max_trials,
      "sphere", result.stop_reason, [&](size_t, double volume_i) {
        const double r = std::cbrt(3 * volume_i / (4 * kPi));
        // A sphere inside the region lies in the box shrunk by r + boundary gap; centres are drawn there.
        const double m = r + options.boundary_gap_mm;
        const Vec3d lo = box.min + Vec3d{m, m, m}, hi = box.max - Vec3d{m, m, m};
        const Vec3d c{lo.x + (hi.x - lo.x) * random.uniform(), lo.y + (hi.y - lo.y) * random.uniform(),
                      lo.z + (hi.z - lo.z) * random.uniform()};
        if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return false;
        if (!(signed_distance_mm(c) <= -m)) return false;
        if (index.any({c.x, c.y, c.z}, r + options.gap_mm, [&](int id) {
              return norm(result.centers_mm[size_t(id)] - c) < result.radii_mm[size_t(id)] + r + options.gap_mm;
            }))
          return false;
        index.insert(int(result.centers_mm.size()), {c.x, c.y, c.z}, r);
        result.centers_mm.push_back(c);
        result.radii_mm.push_back(r);
        return true;
      });
  return result;
}

SignedDistance3 box_region_distance(const Box3& box) {
  if (box.empty() || !is_finite(box.min) || !is_finite(box.max)) throw InvalidInput("box_region_distance needs a finite, non-empty box");
  const Vec3d center = (box.min + box.max) * 0.5, half = (box.max - box.min) * 0.5;
  return [center, half](const Vec3d& p) {
    const Vec3d q{std::fabs(p.x - center.x) - half.x, std::fabs(p.y - center.y) - half.y,
                  std::fabs(p.z - center.z) - half.z};
    const Vec3d outside{std::max(q.x, 0.0), std::max(q.y, 0.0), std::max(q.z, 0.0)};
    return norm(outside) + std::min(std::max({q.x, q.y, q.z}), 0.0);
  };
}

SignedDistance3 sphere_region_distance(const Vec3d& center_mm, double radius_mm) {
  if (!(std::isfinite(radius_mm) && radius_mm > 0) || !is_finite(center_mm))
    throw InvalidInput("sphere_region_distance needs a finite centre and a radius > 0, got " + number(radius_mm));
  return [center_mm, radius_mm](const Vec3d& p) { return norm(p - center_mm) - radius_mm; };
}

UncoveredBoxCount uncovered_box_count(const std::vector<Placement2>& circles, double side, int first, int last) {
  if (first < 0 || last < first + 1 || last > 14)
    throw InvalidInput("uncovered_box_count: expected 0 <= first < last <= 14 box levels");
  constexpr double kPi = 3.14159265358979323846;
  UncoveredBoxCount out;
  for (int k = first; k <= last; ++k) {
    const int n = 1 << k;
    const double eps = side / n;
    std::vector<std::vector<uint32_t>> bins(size_t(n) * size_t(n));
    for (uint32_t i = 0; i < circles.size(); ++i) {
      const Placement2& p = circles[i];
      const double radius = std::sqrt(p.area_mm2 / kPi);
      const int x0 = std::max(0, int((p.center_mm.x - radius) / eps)), x1 = std::min(n - 1, int((p.center_mm.x + radius) / eps));
      const int y0 = std::max(0, int((p.center_mm.y - radius) / eps)), y1 = std::min(n - 1, int((p.center_mm.y + radius) / eps));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) bins[size_t(y) * size_t(n) + size_t(x)].push_back(i);
    }
    uint64_t uncovered = 0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        bool covered = false;
        for (uint32_t i : bins[size_t(y) * size_t(n) + size_t(x)]) {
          const Placement2& p = circles[i];
          const double r2 = p.area_mm2 / kPi;
          bool all = true;
          for (int q = 0; q < 4 && all; ++q) {
            const double dx = (x + (q & 1)) * eps - p.center_mm.x, dy = (y + (q >> 1)) * eps - p.center_mm.y;
            all = dx * dx + dy * dy <= r2;
          }
          if (all) {
            covered = true;
            break;
          }
        }
        uncovered += !covered;
      }
    out.eps_mm.push_back(eps);
    out.boxes.push_back(uncovered);
  }
  double mx = 0, my = 0;
  const double m = double(out.eps_mm.size());
  for (size_t i = 0; i < out.eps_mm.size(); ++i) mx += std::log(1 / out.eps_mm[i]) / m, my += std::log(double(out.boxes[i])) / m;
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < out.eps_mm.size(); ++i) {
    const double x = std::log(1 / out.eps_mm[i]) - mx, y = std::log(double(out.boxes[i])) - my;
    sxy += x * y;
    sxx += x * x;
  }
  out.dimension = sxy / sxx;
  return out;
}

}  // namespace fill
}  // namespace lacuna
