#include "curves/curves.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include "errors.h"

namespace lacuna {
namespace curves {
namespace {

constexpr double kPi = 3.14159265358979323846;

void check_order(int order, int max_order, const char* what) {
  if (order < 1 || order > max_order)
    throw InvalidInput(std::string("the order of a ") + what + " must be between 1 and " + std::to_string(max_order) +
                       ", got " + std::to_string(order));
}

// One of the four patterns A .. D of a recursive curve: its four sub-patterns with a step between them.
struct Pattern {
  int sub[4];
  int step[3][2];  // integer steps between the sub-patterns
};

// Draws patterns on an integer grid, appending a point after every step. Recursion depth is the order.
struct Turtle {
  const Pattern* patterns;
  int64_t x, y;
  std::vector<std::array<int64_t, 2>> points;

  void step(const int* d) {
    x += d[0];
    y += d[1];
    points.push_back({x, y});
  }
  void draw(int pattern, int level) {
    if (level == 0) return;
    const Pattern& p = patterns[pattern];
    for (int s = 0; s < 4; ++s) {
      draw(p.sub[s], level - 1);
      if (s < 3) step(p.step[s]);
    }
  }
};

enum { kA, kB, kC, kD };

// The spec's Hilbert patterns in units of h.
constexpr Pattern kHilbertPatterns[4] = {
    {{kD, kA, kA, kB}, {{-1, 0}, {0, -1}, {1, 0}}},
    {{kC, kB, kB, kA}, {{0, 1}, {1, 0}, {0, -1}}},
    {{kB, kC, kC, kD}, {{1, 0}, {0, 1}, {-1, 0}}},
    {{kA, kD, kD, kC}, {{0, -1}, {-1, 0}, {0, 1}}},
};

// The spec's Sierpinski patterns in units of h.
constexpr Pattern kSierpinskiPatterns[4] = {
    {{kA, kB, kD, kA}, {{1, -1}, {2, 0}, {1, 1}}},
    {{kB, kC, kA, kB}, {{-1, -1}, {0, -2}, {1, -1}}},
    {{kC, kD, kB, kC}, {{-1, 1}, {-2, 0}, {-1, -1}}},
    {{kD, kA, kC, kD}, {{1, 1}, {0, 2}, {-1, 1}}},
};

Vec3d normalized(const Vec3d& v) {
  const double n = norm(v);
  return n > 0 ? v / n : Vec3d{};
}

}  // namespace

Polyline2 hilbert(int order) {
  check_order(order, 12, "Hilbert curve");
  // Cell i along an axis has its centre at -1 + (2i + 1) / 2^k; one step of h is one cell.
  const int64_t n = int64_t(1) << order;
  Turtle t{kHilbertPatterns, n - 1, n - 1, {}};
  t.points.reserve(size_t(n * n));
  t.points.push_back({t.x, t.y});
  t.draw(kA, order);
  Polyline2 out;
  out.points.reserve(t.points.size());
  for (const auto& p : t.points) out.points.push_back({-1 + double(2 * p[0] + 1) / n, -1 + double(2 * p[1] + 1) / n});
  return out;
}

Polyline2 sierpinski(int order) {
  check_order(order, 11, "Sierpinski curve");
  // Integer coordinates count h = 1/2^(k+1) from -1; the start is (-1 + 2h, 1 - h).
  const int64_t m = int64_t(1) << (order + 2);  // 2 / h
  Turtle t{kSierpinskiPatterns, 2, m - 1, {}};
  t.points.reserve(size_t(m * m / 4 + 1));
  t.points.push_back({t.x, t.y});
  static constexpr int kJoin[4][2] = {{1, -1}, {-1, -1}, {-1, 1}, {1, 1}};
  for (int p = kA; p <= kD; ++p) {
    t.draw(p, order);
    t.step(kJoin[p]);
  }
  // The last step of the schema closes the curve; the closed polyline does not repeat its start.
  if (t.points.back() != t.points.front()) throw std::logic_error("the Sierpinski schema did not close");
  t.points.pop_back();
  Polyline2 out;
  out.closed = true;
  out.points.reserve(t.points.size());
  const double h = 2.0 / double(m);
  for (const auto& p : t.points) out.points.push_back({-1 + double(p[0]) * h, -1 + double(p[1]) * h});
  return out;
}

Polyline2 curve(CurveKind kind, int order) { return kind == CurveKind::kHilbert ? hilbert(order) : sierpinski(order); }

namespace {

void check_orders(const std::vector<int>& orders) {
  if (orders.empty()) throw InvalidInput("a superposition needs at least one order");
  std::set<int> seen;
  for (int k : orders)
    if (!seen.insert(k).second) throw InvalidInput("order " + std::to_string(k) + " is repeated in a superposition");
}

}  // namespace

std::vector<Curve2> superposition(CurveKind kind, const std::vector<int>& orders) {
  check_orders(orders);
  std::vector<Curve2> out;
  for (int k : orders) out.push_back({k, curve(kind, k)});
  return out;
}

std::vector<Polyline2> polylines_of(const std::vector<Curve2>& curves) {
  std::vector<Polyline2> out;
  for (const Curve2& c : curves) out.push_back(c.polyline);
  return out;
}

Polyline3 hilbert3d(int order) {
  check_order(order, 8, "3D Hilbert curve");
  const uint32_t n = uint32_t(1) << order;
  const uint64_t count = uint64_t(n) * n * n;
  Polyline3 out;
  out.points.reserve(count);
  for (uint64_t index = 0; index < count; ++index) {
    // The "transpose" of the index: its bits, most significant first, dealt round-robin to X[0], X[1], X[2].
    uint32_t X[3] = {0, 0, 0};
    for (int q = 0; q < 3 * order; ++q) X[q % 3] |= uint32_t((index >> (3 * order - 1 - q)) & 1) << (order - 1 - q / 3);
    // Skilling's TransposetoAxes: Gray decode, then undo the excess rotations and reflections level by level.
    uint32_t t = X[2] >> 1;
    for (int i = 2; i > 0; --i) X[i] ^= X[i - 1];
    X[0] ^= t;
    for (uint32_t Q = 2; Q != n; Q <<= 1) {
      const uint32_t P = Q - 1;
      for (int i = 2; i >= 0; --i) {
        if (X[i] & Q) {
          X[0] ^= P;
        } else {
          t = (X[0] ^ X[i]) & P;
          X[0] ^= t;
          X[i] ^= t;
        }
      }
    }
    out.points.push_back({-1 + double(2 * X[0] + 1) / n, -1 + double(2 * X[1] + 1) / n, -1 + double(2 * X[2] + 1) / n});
  }
  return out;
}

std::vector<Curve3> superposition3d(const std::vector<int>& orders) {
  check_orders(orders);
  std::vector<Curve3> out;
  for (int k : orders) out.push_back({k, hilbert3d(k)});
  return out;
}

std::vector<std::vector<Vec2d>> strokes(const std::vector<Polyline2>& curves, double w) {
  if (!(w > 0) || !std::isfinite(w)) throw InvalidInput("the stroke width must be positive");
  std::vector<std::vector<Vec2d>> out;
  for (const Polyline2& c : curves) {
    const size_t n = c.points.size();
    const size_t segments = n == 0 ? 0 : (c.closed ? n : n - 1);
    for (size_t s = 0; s < segments; ++s) {
      const Vec2d a = c.points[s], b = c.points[(s + 1) % n];
      const Vec2d d = b - a;
      const double length = std::hypot(d.x, d.y);
      const Vec2d t = length > 0 ? d * (0.5 * w / length) : Vec2d{0.5 * w, 0};  // half-width along the segment
      const Vec2d left{-t.y, t.x};
      out.push_back({a - t - left, b + t - left, b + t + left, a - t + left});
    }
  }
  return out;
}

namespace {

struct Box2 {
  double x0, y0, x1, y1;
};

// Sutherland-Hodgman against the four sides of an axis-aligned box; points on a side are set exactly on it.
std::vector<Vec2d> clip_to_box(const std::vector<Vec2d>& polygon, const Box2& box) {
  std::vector<Vec2d> in = polygon, out;
  for (int side = 0; side < 4; ++side) {
    const int axis = side % 2;  // 0: x, 1: y
    const double bound = side == 0 ? box.x0 : side == 1 ? box.y0 : side == 2 ? box.x1 : box.y1;
    const double sign = side < 2 ? 1 : -1;  // inside: sign * (coordinate - bound) >= 0
    auto coord = [axis](const Vec2d& p) { return axis == 0 ? p.x : p.y; };
    out.clear();
    for (size_t i = 0; i < in.size(); ++i) {
      const Vec2d p = in[i], q = in[(i + 1) % in.size()];
      const double dp = sign * (coord(p) - bound), dq = sign * (coord(q) - bound);
      if (dp >= 0) out.push_back(p);
      if ((dp >= 0) != (dq >= 0) && dp != 0 && dq != 0) {
        const double f = dp / (dp - dq);
        Vec2d r = p + (q - p) * f;
        (axis == 0 ? r.x : r.y) = bound;
        out.push_back(r);
      }
    }
    std::swap(in, out);
    if (in.size() < 3) return {};
  }
  return in;
}

// Whether the convex polygon (orientation `sign`: +1 counter-clockwise) contains point c, border included.
bool contains(const std::vector<Vec2d>& p, double sign, const Vec2d& c) {
  for (size_t i = 0; i < p.size(); ++i) {
    const Vec2d a = p[i], b = p[(i + 1) % p.size()];
    if (sign * cross2(b - a, c - a) < 0) return false;
  }
  return true;
}

Box2 bounds(const std::vector<Vec2d>& p) {
  Box2 b{HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const Vec2d& v : p) b = {std::min(b.x0, v.x), std::min(b.y0, v.y), std::max(b.x1, v.x), std::max(b.y1, v.y)};
  return b;
}

// The union area of convex polygons that all lie inside [x0, x1] in x (clipped to one cell).
double union_area_in_cell(const std::vector<std::vector<Vec2d>>& polys, double x0, double x1) {
  if (polys.size() == 1) return std::fabs(signed_area(polys[0]));
  std::vector<Box2> box;
  for (const auto& p : polys) box.push_back(bounds(p));
  std::vector<double> xs{x0, x1};
  for (const auto& p : polys)
    for (const Vec2d& v : p) xs.push_back(v.x);
  // The cross-sections' endpoints change order only where edges of two polygons cross.
  for (size_t a = 0; a < polys.size(); ++a)
    for (size_t b = a + 1; b < polys.size(); ++b) {
      if (box[a].x1 < box[b].x0 || box[b].x1 < box[a].x0 || box[a].y1 < box[b].y0 || box[b].y1 < box[a].y0) continue;
      const auto& P = polys[a];
      const auto& Q = polys[b];
      for (size_t i = 0; i < P.size(); ++i) {
        const Vec2d p = P[i], r = P[(i + 1) % P.size()] - p;
        for (size_t j = 0; j < Q.size(); ++j) {
          const Vec2d q = Q[j], s = Q[(j + 1) % Q.size()] - q;
          const double den = cross2(r, s);
          if (den == 0) continue;  // parallel edges never swap the order of endpoints
          const double t = cross2(q - p, s) / den, u = cross2(q - p, r) / den;
          // A loose test: an extra abscissa only adds a slab.
          constexpr double kSlack = 1e-9;
          if (t >= -kSlack && t <= 1 + kSlack && u >= -kSlack && u <= 1 + kSlack) {
            const double x = p.x + t * r.x;
            if (x > x0 && x < x1) xs.push_back(x);
          }
        }
      }
    }
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  double area = 0;
  std::vector<std::pair<double, double>> spans;
  for (size_t k = 0; k + 1 < xs.size(); ++k) {
    const double xm = 0.5 * (xs[k] + xs[k + 1]);
    spans.clear();
    for (size_t a = 0; a < polys.size(); ++a) {
      if (!(box[a].x0 < xm && xm < box[a].x1)) continue;
      double lo = HUGE_VAL, hi = -HUGE_VAL;
      const auto& P = polys[a];
      for (size_t i = 0; i < P.size(); ++i) {
        const Vec2d p = P[i], q = P[(i + 1) % P.size()];
        if ((p.x < xm) == (q.x < xm)) continue;
        const double y = p.y + (xm - p.x) * (q.y - p.y) / (q.x - p.x);
        lo = std::min(lo, y);
        hi = std::max(hi, y);
      }
      if (lo < hi) spans.push_back({lo, hi});
    }
    std::sort(spans.begin(), spans.end());
    if (spans.empty()) continue;
    double length = 0, lo = spans[0].first, hi = spans[0].second;
    for (const auto& s : spans) {
      if (s.first > hi) {
        length += hi - lo;
        lo = s.first;
      }
      hi = std::max(hi, s.second);
    }
    length += hi - lo;
    area += length * (xs[k + 1] - xs[k]);
  }
  return area;
}

}  // namespace

double convex_union_area(const std::vector<std::vector<Vec2d>>& polygons, const Vec2d& clip_min,
                         const Vec2d& clip_max) {
  if (!(clip_min.x < clip_max.x && clip_min.y < clip_max.y) || !std::isfinite(clip_min.x) ||
      !std::isfinite(clip_min.y) || !std::isfinite(clip_max.x) || !std::isfinite(clip_max.y))
    throw InvalidInput("the clipping box of a union area must be finite and non-empty");
  std::vector<size_t> kept;
  std::vector<Box2> box;
  std::vector<double> sign;
  for (size_t i = 0; i < polygons.size(); ++i) {
    const auto& p = polygons[i];
    if (p.size() < 3) continue;
    const Box2 b = bounds(p);
    if (b.x1 <= clip_min.x || b.x0 >= clip_max.x || b.y1 <= clip_min.y || b.y0 >= clip_max.y) continue;
    const double a = signed_area(p);
    if (a == 0) continue;
    kept.push_back(i);
    box.push_back(b);
    sign.push_back(a > 0 ? 1 : -1);
  }
  if (kept.empty()) return 0;

  // About one polygon per cell, fewer cells when polygons are large (bounded bin entries).
  int cells = std::clamp(int(std::ceil(std::sqrt(double(kept.size())))), 1, 2048);
  const double width = clip_max.x - clip_min.x, height = clip_max.y - clip_min.y;
  auto grid_x = [&](int i) { return i == cells ? clip_max.x : clip_min.x + width * i / cells; };
  auto grid_y = [&](int j) { return j == cells ? clip_max.y : clip_min.y + height * j / cells; };
  // The last cell whose lower bound is at or below v (clamped to the grid).
  auto cell_of = [&](double v, double lo, double extent, const auto& grid) {
    int i = std::clamp(int(std::floor((v - lo) / extent * cells)), 0, cells - 1);
    while (i > 0 && grid(i) > v) --i;
    while (i + 1 < cells && grid(i + 1) <= v) ++i;
    return i;
  };
  std::vector<std::array<int, 4>> range(kept.size());
  size_t entries = 0;
  for (;;) {
    entries = 0;
    for (size_t k = 0; k < kept.size(); ++k) {
      range[k] = {cell_of(box[k].x0, clip_min.x, width, grid_x), cell_of(box[k].y0, clip_min.y, height, grid_y),
                  cell_of(box[k].x1, clip_min.x, width, grid_x), cell_of(box[k].y1, clip_min.y, height, grid_y)};
      entries += size_t(range[k][2] - range[k][0] + 1) * size_t(range[k][3] - range[k][1] + 1);
    }
    if (entries <= 20000000 || cells == 1) break;
    cells = std::max(1, cells / 2);
  }
  // Bins as compressed rows: start[c] .. start[c + 1] in `members`.
  std::vector<size_t> start(size_t(cells) * cells + 1, 0);
  for (const auto& r : range)
    for (int j = r[1]; j <= r[3]; ++j)
      for (int i = r[0]; i <= r[2]; ++i) ++start[size_t(j) * cells + i + 1];
  for (size_t c = 0; c + 1 < start.size(); ++c) start[c + 1] += start[c];
  std::vector<uint32_t> members(entries);
  std::vector<size_t> fill(start.begin(), start.end() - 1);
  for (size_t k = 0; k < kept.size(); ++k)
    for (int j = range[k][1]; j <= range[k][3]; ++j)
      for (int i = range[k][0]; i <= range[k][2]; ++i) members[fill[size_t(j) * cells + i]++] = uint32_t(k);

  double area = 0;
  std::vector<std::vector<Vec2d>> local;
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      const Box2 cell{grid_x(i), grid_y(j), grid_x(i + 1), grid_y(j + 1)};
      const Vec2d corners[4] = {{cell.x0, cell.y0}, {cell.x1, cell.y0}, {cell.x1, cell.y1}, {cell.x0, cell.y1}};
      local.clear();
      bool covered = false;
      const size_t c = size_t(j) * cells + i;
      for (size_t m = start[c]; m < start[c + 1] && !covered; ++m) {
        const uint32_t k = members[m];
        const Box2& b = box[k];
        if (b.x1 <= cell.x0 || b.x0 >= cell.x1 || b.y1 <= cell.y0 || b.y0 >= cell.y1) continue;
        const auto& p = polygons[kept[k]];
        covered = std::all_of(corners, corners + 4, [&](const Vec2d& q) { return contains(p, sign[k], q); });
        if (!covered) {
          std::vector<Vec2d> clipped = clip_to_box(p, cell);
          if (!clipped.empty()) local.push_back(std::move(clipped));
        }
      }
      if (covered)
        area += (cell.x1 - cell.x0) * (cell.y1 - cell.y0);
      else if (!local.empty())
        area += union_area_in_cell(local, cell.x0, cell.x1);
    }
  return area;
}

double fill_rate_estimate(const std::vector<Polyline2>& curves, double w) {
  if (!(w > 0) || !std::isfinite(w)) throw InvalidInput("the stroke width must be positive");
  double length = 0;
  for (const Polyline2& c : curves) {
    const size_t n = c.points.size();
    const size_t segments = n == 0 ? 0 : (c.closed ? n : n - 1);
    for (size_t s = 0; s < segments; ++s) {
      const Vec2d d = c.points[(s + 1) % n] - c.points[s];
      length += std::hypot(d.x, d.y);
    }
  }
  return length * w / 4;
}

double fill_rate_exact(const std::vector<Polyline2>& curves, double w) {
  return convex_union_area(strokes(curves, w), {-1, -1}, {1, 1}) / 4;
}

TubeFootprint::TubeFootprint(const std::vector<Polyline3>& lines, double radius) : radius_(radius) {
  if (!(radius > 0) || !std::isfinite(radius)) throw InvalidInput("the tube radius must be a positive length");
  lo_ = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
  hi_ = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const Polyline3& line : lines) {
    const size_t count = line.points.size();
    for (size_t i = 0; i + 1 < count + (line.closed && count > 2 ? 1 : 0); ++i)
      segments_.emplace_back(line.points[i], line.points[(i + 1) % count]);
    if (count == 1) segments_.emplace_back(line.points[0], line.points[0]);
    for (const Vec3d& p : line.points)
      for (int k = 0; k < 3; ++k) lo_[k] = std::min(lo_[k], p[k] - radius), hi_[k] = std::max(hi_[k], p[k] + radius);
  }
  if (segments_.empty()) return;
  cell_ = 2 * radius;
  for (int k = 0; k < 3; ++k) cell_ = std::max(cell_, (hi_[k] - lo_[k]) / 256);
  for (int k = 0; k < 3; ++k) dims_[k] = std::max(1, int(std::ceil((hi_[k] - lo_[k]) / cell_)));
  buckets_.resize(size_t(dims_[0]) * size_t(dims_[1]) * size_t(dims_[2]));
  for (size_t s = 0; s < segments_.size(); ++s) {
    const auto& [a, b] = segments_[s];
    int c0[3], c1[3];
    for (int k = 0; k < 3; ++k) {
      c0[k] = cell_of(std::min(a[k], b[k]) - radius, k);
      c1[k] = cell_of(std::max(a[k], b[k]) + radius, k);
    }
    for (int x = c0[0]; x <= c1[0]; ++x)
      for (int y = c0[1]; y <= c1[1]; ++y)
        for (int z = c0[2]; z <= c1[2]; ++z)
          buckets_[(size_t(x) * size_t(dims_[1]) + size_t(y)) * size_t(dims_[2]) + size_t(z)].push_back(uint32_t(s));
  }
}

int TubeFootprint::cell_of(double v, int k) const {
  return std::clamp(int(std::floor((v - lo_[k]) / cell_)), 0, dims_[k] - 1);
}

bool TubeFootprint::covers(const Vec3d& p) const {
  if (segments_.empty()) return false;
  for (int k = 0; k < 3; ++k)
    if (!(p[k] >= lo_[k] && p[k] <= hi_[k])) return false;
  const double r2 = radius_ * radius_;
  for (uint32_t s : buckets_[(size_t(cell_of(p.x, 0)) * size_t(dims_[1]) + size_t(cell_of(p.y, 1))) * size_t(dims_[2]) +
                             size_t(cell_of(p.z, 2))]) {
    const auto& [a, b] = segments_[s];
    if (point_segment_distance2(p, a, b) <= r2) return true;
  }
  return false;
}

SurfaceCoverage surface_coverage(const SurfaceMap& map, const TubeFootprint& footprint, int n, int row_begin,
                                 int row_end) {
  if (!map.point) throw InvalidInput("surface_coverage: the map has no points");
  if (n < 16 || n > 20000) throw InvalidInput("the samples per side must be from 16 to 20000");
  const double step = 2.0 / n, d = 1e-3 * step;
  // One point per cell at a fixed pseudo-random place in it (stratified sampling): a regular grid of
  // midpoints aliases with the curves' own lattice (tube edges parallel to rows of samples), which
  // moved the rate by a few percent from one n to the next; jittered, it converges.
  auto jitter = [](uint64_t key) {
    key += 0x9e3779b97f4a7c15ull;
    key = (key ^ (key >> 30)) * 0xbf58476d1ce4e5b9ull;
    key = (key ^ (key >> 27)) * 0x94d049bb133111ebull;
    key ^= key >> 31;
    return double(key >> 11) * 0x1.0p-53;
  };
  SurfaceCoverage out;
  for (int j = std::max(row_begin, 0); j < std::min(row_end, n); ++j) {
    for (int i = 0; i < n; ++i) {
      const uint64_t cell = uint64_t(j) * uint64_t(n) + uint64_t(i);
      const double X = -1 + (i + jitter(2 * cell)) * step, Y = -1 + (j + jitter(2 * cell + 1)) * step;
      const Vec3d du = (map.point(X + d, Y) - map.point(X - d, Y)) / (2 * d);
      const Vec3d dv = (map.point(X, Y + d) - map.point(X, Y - d)) / (2 * d);
      const double element = norm(cross(du, dv)) * step * step;
      out.area += element;
      if (footprint.covers(map.point(X, Y))) out.covered_area += element;
      ++out.samples;
    }
  }
  return out;
}

SurfaceMap sphere_map() {
  SurfaceMap m;
  m.name = "sphere";
  m.point = [](double X, double Y) {
    const double r2 = X * X + Y * Y, s = r2 + 1;
    return Vec3d{2 * X / s, 2 * Y / s, (r2 - 1) / s};
  };
  m.normal = [p = m.point](double X, double Y) { return normalized(p(X, Y)); };
  return m;
}

SurfaceMap cylinder_map() {
  SurfaceMap m;
  m.name = "cylinder";
  m.point = [](double X, double Y) { return Vec3d{std::sin(kPi * X), Y, std::cos(kPi * X)}; };
  m.normal = [](double X, double) { return Vec3d{std::sin(kPi * X), 0, std::cos(kPi * X)}; };
  return m;
}

SurfaceMap torus_map() {
  SurfaceMap m;
  m.name = "torus";
  m.point = [](double X, double Y) {
    const double r = std::sin(kPi * X) - 1.5;
    return Vec3d{std::cos(kPi * Y) * r, std::sin(kPi * Y) * r, std::cos(kPi * X)};
  };
  // From the centre of the tube's circle, (-1.5 cos(pi Y), -1.5 sin(pi Y), 0), to the point: unit length.
  m.normal = [](double X, double Y) {
    const double s = std::sin(kPi * X);
    return Vec3d{std::cos(kPi * Y) * s, std::sin(kPi * Y) * s, std::cos(kPi * X)};
  };
  return m;
}

SurfaceMap cone_map() {
  SurfaceMap m;
  m.name = "cone";
  m.point = [](double X, double Y) {
    const double r = 0.5 * (1 - Y);
    return Vec3d{r * std::sin(kPi * X), Y, r * std::cos(kPi * X)};
  };
  // The gradient of sqrt(x^2 + z^2) - (1 - y) / 2.
  m.normal = [](double X, double) { return Vec3d{std::sin(kPi * X), 0.5, std::cos(kPi * X)} / std::sqrt(1.25); };
  return m;
}

namespace {

// The degree + 1 non-zero B-spline basis functions at t in [0, 1] for `count` control points with clamped
// uniform knots, and the index of the first one (Piegl and Tiller, A2.2).
int bspline_basis(int degree, int count, double t, double* basis) {
  const int pieces = count - degree;
  auto knot = [&](int j) { return j <= degree ? 0.0 : j >= count ? 1.0 : double(j - degree) / pieces; };
  t = std::clamp(t, 0.0, 1.0);
  const int span = degree + std::min(int(std::floor(t * pieces)), pieces - 1);
  double left[16], right[16];
  basis[0] = 1;
  for (int j = 1; j <= degree; ++j) {
    left[j] = t - knot(span + 1 - j);
    right[j] = knot(span + j) - t;
    double saved = 0;
    for (int r = 0; r < j; ++r) {
      const double temp = basis[r] / (right[r + 1] + left[j - r]);
      basis[r] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    basis[j] = saved;
  }
  return span - degree;
}

}  // namespace

SurfaceMap bspline_map(const BSplinePatch& patch) {
  const BSplinePatch& b = patch;
  if (b.degree_u < 1 || b.degree_v < 1 || b.degree_u > 15 || b.degree_v > 15)
    throw InvalidInput("a B-spline patch's degrees must be between 1 and 15");
  if (b.count_u <= b.degree_u || b.count_v <= b.degree_v)
    throw InvalidInput("a B-spline patch needs more control points than its degree along u and v");
  if (b.control_points.size() != size_t(b.count_u) * size_t(b.count_v))
    throw InvalidInput("a B-spline patch needs count_u * count_v = " + std::to_string(size_t(b.count_u) * b.count_v) +
                       " control points, got " + std::to_string(b.control_points.size()));
  for (const Vec3d& p : b.control_points)
    if (!is_finite(p)) throw InvalidInput("a B-spline patch's control points must be finite");
  SurfaceMap m;
  m.name = "bspline";
  m.point = [b](double X, double Y) {
    double nu[16], nv[16];
    const int i0 = bspline_basis(b.degree_u, b.count_u, 0.5 * (X + 1), nu);
    const int j0 = bspline_basis(b.degree_v, b.count_v, 0.5 * (Y + 1), nv);
    Vec3d p;
    for (int j = 0; j <= b.degree_v; ++j)
      for (int i = 0; i <= b.degree_u; ++i)
        p += b.control_points[size_t(i0 + i) + size_t(b.count_u) * size_t(j0 + j)] * (nu[i] * nv[j]);
    return p;
  };
  return m;
}

namespace {

// The Petrie hexagon of the cube and the faces of the tour (see cube_face_map()).
constexpr Vec3d kTourCorner[6] = {{1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, 1, 1}, {-1, -1, 1}, {1, -1, 1}};
constexpr Vec3d kTourNormal[6] = {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}, {-1, 0, 0}, {0, 0, 1}, {0, -1, 0}};

}  // namespace

SurfaceMap cube_face_map(int face) {
  if (face < 0 || face > 5) throw InvalidInput("a cube face is numbered 0 to 5, got " + std::to_string(face));
  const Vec3d n = kTourNormal[face], v0 = kTourCorner[face], v1 = kTourCorner[(face + 1) % 6];
  const Vec3d a = (v0 + v1) * 0.5 - n;  // towards the edge V_f V_(f+1), unit
  const Vec3d b = (v0 - v1) * 0.5;      // along that edge towards V_f, unit
  SurfaceMap m;
  m.name = "cube face " + std::to_string(face);
  m.point = [n, a, b](double X, double Y) { return n + a * X + b * Y; };
  m.normal = [n](double, double) { return n; };
  return m;
}

Vec3d surface_normal(const SurfaceMap& map, double X, double Y) {
  if (map.normal) return map.normal(X, Y);
  constexpr double kStep = 1e-6;
  const double x0 = std::max(X - kStep, -1.0), x1 = std::min(X + kStep, 1.0);
  const double y0 = std::max(Y - kStep, -1.0), y1 = std::min(Y + kStep, 1.0);
  return normalized(cross(map.point(x1, Y) - map.point(x0, Y), map.point(X, y1) - map.point(X, y0)));
}

namespace {

void check_map_options(const MapOptions& o) {
  if (!(o.scale > 0) || !std::isfinite(o.scale)) throw InvalidInput("the map's scale must be positive");
  if (!std::isfinite(o.offset_mm)) throw InvalidInput("the map's offset must be finite (mm)");
  if (!(o.tolerance_mm > 0)) throw InvalidInput("the map's tolerance must be positive (mm)");
  if (o.max_depth < 0 || o.max_depth > 40) throw InvalidInput("the map's max_depth must be between 0 and 40");
}

}  // namespace

Polyline3 map_polyline(const Polyline2& polyline, const SurfaceMap& map, const MapOptions& o) {
  if (!map.point) throw InvalidInput("the surface map '" + map.name + "' has no point function");
  check_map_options(o);
  auto place = [&](const Vec2d& q) {
    Vec3d p = map.point(q.x, q.y) * o.scale;
    if (o.offset_mm != 0) p += surface_normal(map, q.x, q.y) * o.offset_mm;
    return p;
  };
  Polyline3 out;
  out.closed = polyline.closed;
  // Appends the points strictly inside segment a-b (images pa, pb), in order.
  std::function<void(const Vec2d&, const Vec3d&, const Vec2d&, const Vec3d&, int)> split =
      [&](const Vec2d& a, const Vec3d& pa, const Vec2d& b, const Vec3d& pb, int depth) {
        if (depth >= o.max_depth) return;
        const Vec2d m = (a + b) * 0.5;
        const Vec3d pm = place(m);
        if (norm((pa + pb) * 0.5 - pm) <= o.tolerance_mm) return;
        split(a, pa, m, pm, depth + 1);
        if (out.points.size() >= o.max_points)
          throw ResourceLimit("mapping onto '" + map.name + "' would make more than " + std::to_string(o.max_points) +
                              " points (the memory budget's share); raise tolerance_mm");
        out.points.push_back(pm);
        split(m, pm, b, pb, depth + 1);
      };
  const size_t n = polyline.points.size();
  if (n == 0) return out;
  Vec3d pa = place(polyline.points[0]);
  out.points.push_back(pa);
  const size_t segments = polyline.closed ? n : n - 1;
  for (size_t s = 0; s < segments; ++s) {
    const Vec2d a = polyline.points[s], b = polyline.points[(s + 1) % n];
    const Vec3d pb = s + 1 == n ? out.points.front() : place(b);
    split(a, pa, b, pb, 0);
    if (s + 1 < n) out.points.push_back(pb);
    pa = pb;
  }
  return out;
}

std::vector<Polyline3> cube_curve(CurveKind kind, int order, const MapOptions& o) {
  check_map_options(o);
  const Polyline2 square = curve(kind, order);
  std::vector<Polyline3> out;
  if (kind == CurveKind::kSierpinski) {
    for (int f = 0; f < 6; ++f) {
      const SurfaceMap face = cube_face_map(f);
      Polyline3 loop;
      loop.closed = true;
      for (const Vec2d& q : square.points)
        loop.points.push_back(face.point(q.x, q.y) * o.scale + kTourNormal[f] * o.offset_mm);
      out.push_back(std::move(loop));
    }
    return out;
  }
  const double d = 1.0 / double(int64_t(1) << order);
  Polyline3 tour;
  tour.closed = true;
  for (int f = 0; f < 6; ++f) {
    const SurfaceMap face = cube_face_map(f);
    for (const Vec2d& q : square.points)
      tour.points.push_back(face.point(q.x, q.y) * o.scale + kTourNormal[f] * o.offset_mm);
    // H_k ends at (1 - d, -1 + d); the joint point is its foot on the edge X = 1, which the next face shares.
    const Vec3d joint = face.point(1, -1 + d);
    tour.points.push_back(joint * o.scale + (kTourNormal[f] + kTourNormal[(f + 1) % 6]) * o.offset_mm);
  }
  out.push_back(std::move(tour));
  return out;
}

}  // namespace curves
}  // namespace lacuna
