#include "layers/layers.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace lacuna {
namespace {

// x + y = hi + lo exactly (Knuth's two-sum), and x * y = hi + lo exactly (a fused multiply-add).
void two_sum(double x, double y, double& hi, double& lo) {
  hi = x + y;
  const double yv = hi - x, xv = hi - yv;
  lo = (x - xv) + (y - yv);
}
void two_product(double x, double y, double& hi, double& lo) {
  hi = x * y;
  lo = std::fma(x, y, -hi);
}

// The sign of (b - a) x (c - a), exactly (+1 counter-clockwise, -1 clockwise, 0 collinear): the doubles are trusted beyond Shewchuk's error bound
// (ccwerrboundA); otherwise every difference and product is split into exact pairs of doubles and
// their sum kept as an exact expansion. Points on one straight contour stay collinear, so the
// check below never takes rounding for a crossing.
int orientation(const Vec2d& a, const Vec2d& b, const Vec2d& c) {
  const double left = (a.x - c.x) * (b.y - c.y), right = (a.y - c.y) * (b.x - c.x);
  const double det = left - right;
  constexpr double kEpsilon = 1.1102230246251565e-16;  // 2^-53
  const double bound = (3.0 + 16.0 * kEpsilon) * kEpsilon * (std::fabs(left) + std::fabs(right));
  if (det > bound) return 1;
  if (-det > bound) return -1;
  double d[4][2];  // a.x - c.x, b.y - c.y, a.y - c.y, b.x - c.x, each as hi + lo
  two_sum(a.x, -c.x, d[0][0], d[0][1]);
  two_sum(b.y, -c.y, d[1][0], d[1][1]);
  two_sum(a.y, -c.y, d[2][0], d[2][1]);
  two_sum(b.x, -c.x, d[3][0], d[3][1]);
  std::vector<double> expansion;  // nonoverlapping, by increasing magnitude; sums to what is added
  auto add = [&](double x) {
    for (double& e : expansion) two_sum(x, e, x, e);
    expansion.push_back(x);
  };
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      double hi, lo;
      two_product(d[0][i], d[1][j], hi, lo);
      add(hi), add(lo);
      two_product(-d[2][i], d[3][j], hi, lo);
      add(hi), add(lo);
    }
  for (auto e = expansion.rbegin(); e != expansion.rend(); ++e)
    if (*e != 0) return *e > 0 ? 1 : -1;
  return 0;
}

// Whether closed segments ab and cd share a point (exact orientations).
bool segments_meet(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d), o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 == 0 && o2 == 0 && o3 == 0 && o4 == 0) {  // collinear: do their projections overlap?
    const bool along_x = std::abs(b.x - a.x) + std::abs(d.x - c.x) >= std::abs(b.y - a.y) + std::abs(d.y - c.y);
    auto key = [&](const Vec2d& p) { return along_x ? p.x : p.y; };
    return std::max(std::min(key(a), key(b)), std::min(key(c), key(d))) <=
           std::min(std::max(key(a), key(b)), std::max(key(c), key(d)));
  }
  return o1 * o2 <= 0 && o3 * o4 <= 0;
}

}  // namespace

std::vector<uint8_t> coverage_image(const std::vector<float>& distance, const LayerGrid& grid) {
  const int w = grid.width, h = grid.height;
  std::vector<uint8_t> image(distance.size());
  const double px = grid.pixel_mm, py = grid.pixel_y_mm();
  auto at = [&](int i, int j) { return double(distance[size_t(j) * size_t(w) + size_t(i)]); };
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const double d = at(i, j);
      // The distance within the plane: the 3D distance over the gradient's horizontal part (central
      // differences), so a surface nearly parallel to the layer covers no more than it cuts.
      const double gx = (at(std::min(i + 1, w - 1), j) - at(std::max(i - 1, 0), j)) /
                        (double(std::min(i + 1, w - 1) - std::max(i - 1, 0)) * px);
      const double gy = (at(i, std::min(j + 1, h - 1)) - at(i, std::max(j - 1, 0))) /
                        (double(std::min(j + 1, h - 1) - std::max(j - 1, 0)) * py);
      const double g = std::hypot(gx, gy);
      uint8_t& v = image[size_t(j) * size_t(w) + size_t(i)];
      if (!(g > 1e-3)) {
        // The surface parallel to the layer here (a horizontal face on the layer's plane): no crossing to place
        // within the pixel, only a side; the contours' reading (inside where d < 0) decides, as it does for them.
        v = d < 0 ? 255 : 0;
        continue;
      }
      // The pixel's width across the boundary (its normal along the gradient).
      const double across = (std::abs(gx) * px + std::abs(gy) * py) / g;
      v = uint8_t(std::lround(255 * std::clamp(0.5 - d / (g * across), 0.0, 1.0)));
    }
  }
  return image;
}

double image_area_mm2(const std::vector<uint8_t>& image, const LayerGrid& grid) {
  uint64_t sum = 0;
  for (uint8_t v : image) sum += v;
  return double(sum) / 255 * grid.pixel_mm * grid.pixel_y_mm();
}

Contours contour_layer(const std::vector<float>& f, const LayerGrid& grid) {
  const int w = grid.width, h = grid.height;
  Contours contours;
  if (w < 2 || h < 2) return contours;
  auto inside = [&](int i, int j) { return f[size_t(j) * size_t(w) + size_t(i)] < 0; };
  // A crossing is named by its grid edge: 2 * pixel (+0 the edge towards +x, +1 towards +y).
  auto edge_key = [&](int i, int j, int dir) { return 2 * (int64_t(j) * w + i) + dir; };
  auto crossing = [&](int64_t key) {
    const int64_t pixel = key / 2;
    const int i = int(pixel % w), j = int(pixel / w);
    const int i1 = key % 2 == 0 ? i + 1 : i, j1 = key % 2 == 0 ? j : j + 1;
    const double f0 = f[size_t(j) * size_t(w) + size_t(i)], f1 = f[size_t(j1) * size_t(w) + size_t(i1)];
    // Kept a hundredth of a pixel off the samples, so crossings on two edges of one sample stay
    // apart when written with a file's resolution.
    const double t = std::clamp(f0 / (f0 - f1), 0.01, 0.99);
    return Vec2d{grid.origin_mm.x + (i + (i1 - i) * t) * grid.pixel_mm,
                 grid.origin_mm.y + (j + (j1 - j) * t) * grid.pixel_y_mm()};
  };
  // next[a] = b: the segment leaving crossing a ends at crossing b (the solid on its left).
  std::vector<int64_t> next(size_t(2) * grid.pixels(), -1);
  std::vector<int64_t> starts;
  for (int j = 0; j + 1 < h; ++j) {
    for (int i = 0; i + 1 < w; ++i) {
      // Corners counter-clockwise and the edge from each to the next, walked counter-clockwise.
      const bool in[4] = {inside(i, j), inside(i + 1, j), inside(i + 1, j + 1), inside(i, j + 1)};
      if (in[0] == in[1] && in[1] == in[2] && in[2] == in[3]) continue;
      const int64_t edges[4] = {edge_key(i, j, 0), edge_key(i + 1, j, 1), edge_key(i, j + 1, 0), edge_key(i, j, 1)};
      // Crossings in walking order; leaving the solid (in -> out) or entering it.
      int64_t leave[2], enter[2];
      int leaves = 0, enters = 0, leave_at[2] = {0, 0}, enter_at[2] = {0, 0};
      for (int k = 0; k < 4; ++k) {
        if (in[k] == in[(k + 1) % 4]) continue;
        if (in[k]) {
          leave_at[leaves] = k;
          leave[leaves++] = edges[k];
        } else {
          enter_at[enters] = k;
          enter[enters++] = edges[k];
        }
      }
      auto link = [&](int64_t a, int64_t b) {
        next[size_t(a)] = b;
        starts.push_back(a);
      };
      if (leaves == 1) {
        link(leave[0], enter[0]);
        continue;
      }
      // A saddle: the solid joins through the cell's centre when its mean is inside; then each
      // crossing that leaves pairs with the next that enters (walking on), else with the one before.
      const double mean = (double(f[size_t(j) * w + i]) + f[size_t(j) * w + i + 1] + f[size_t(j + 1) * w + i + 1] +
                           f[size_t(j + 1) * w + i]) / 4;
      for (int a = 0; a < 2; ++a) {
        int best = -1;
        for (int b = 0; b < 2; ++b) {
          const int steps = mean < 0 ? (enter_at[b] - leave_at[a] + 4) % 4 : (leave_at[a] - enter_at[b] + 4) % 4;
          if (steps == 1) best = b;
        }
        link(leave[a], enter[best]);
      }
    }
  }
  std::sort(starts.begin(), starts.end());
  for (int64_t s : starts) {
    if (next[size_t(s)] < 0) continue;  // already on a contour
    std::vector<Vec2d> loop;
    int64_t at = s;
    while (next[size_t(at)] >= 0) {
      loop.push_back(crossing(at));
      const int64_t to = next[size_t(at)];
      next[size_t(at)] = -1;
      at = to;
    }
    if (loop.size() >= 3) contours.push_back(std::move(loop));
  }
  return contours;
}

Contours simplify_contours(const Contours& contours, double tolerance_mm) {
  Contours out;
  out.reserve(contours.size());
  for (const std::vector<Vec2d>& loop : contours) {
    const size_t n = loop.size();
    if (tolerance_mm <= 0 || n < 5) {
      out.push_back(loop);
      continue;
    }
    size_t far = 0;
    double far_d = -1;
    for (size_t i = 1; i < n; ++i) {
      const double d = std::hypot(loop[i].x - loop[0].x, loop[i].y - loop[0].y);
      if (d > far_d) far_d = d, far = i;
    }
    std::vector<char> keep(n, 0);
    keep[0] = keep[far] = 1;
    // Chains [first, last] in loop order (last may wrap past the end).
    std::vector<std::pair<size_t, size_t>> stack = {{0, far}, {far, n}};
    while (!stack.empty()) {
      const auto [first, last] = stack.back();
      stack.pop_back();
      const Vec2d& a = loop[first % n];
      const Vec2d& b = loop[last % n];
      double worst = -1;
      size_t at = first;
      for (size_t k = first + 1; k < last; ++k) {
        const double d = point_segment_distance(loop[k % n], a, b);
        if (d > worst) worst = d, at = k;
      }
      if (worst > tolerance_mm) {
        keep[at % n] = 1;
        stack.push_back({first, at});
        stack.push_back({at, last});
      }
    }
    std::vector<Vec2d> reduced;
    for (size_t i = 0; i < n; ++i)
      if (keep[i]) reduced.push_back(loop[i]);
    out.push_back(reduced.size() >= 4 ? std::move(reduced) : loop);
  }
  return out;
}

double contours_area_mm2(const Contours& contours) {
  double area = 0;
  for (const auto& loop : contours) area += signed_area(loop);
  return area;
}

double contours_length_mm(const Contours& contours) {
  double length = 0;
  for (const auto& loop : contours)
    for (size_t i = 0, n = loop.size(); i < n; ++i)
      length += std::hypot(loop[(i + 1) % n].x - loop[i].x, loop[(i + 1) % n].y - loop[i].y);
  return length;
}

ContourCheck check_contours(const Contours& contours) {
  ContourCheck check;
  check.loops = contours.size();
  struct Segment {
    uint32_t loop, index;  // the segment from vertex index to index + 1 of its loop
  };
  std::vector<Segment> segments;
  double lo_x = HUGE_VAL, lo_y = HUGE_VAL, hi_x = -HUGE_VAL, hi_y = -HUGE_VAL;
  for (size_t l = 0; l < contours.size(); ++l) {
    const auto& loop = contours[l];
    if (loop.size() < 3) {
      check.closed = false;
      check.problems.push_back("contour " + std::to_string(l) + " has " + std::to_string(loop.size()) + " points");
      continue;
    }
    for (size_t i = 0; i < loop.size(); ++i) {
      if (!std::isfinite(loop[i].x) || !std::isfinite(loop[i].y)) {
        check.closed = false;
        check.problems.push_back("contour " + std::to_string(l) + " has a non-finite point");
        return check;
      }
      lo_x = std::min(lo_x, loop[i].x), hi_x = std::max(hi_x, loop[i].x);
      lo_y = std::min(lo_y, loop[i].y), hi_y = std::max(hi_y, loop[i].y);
      segments.push_back({uint32_t(l), uint32_t(i)});
    }
  }
  if (segments.empty() || !check.closed) return check;
  auto end_points = [&](const Segment& s) {
    const auto& loop = contours[s.loop];
    return std::pair<const Vec2d&, const Vec2d&>(loop[s.index], loop[(s.index + 1) % loop.size()]);
  };
  // Buckets: a grid of about one cell per segment.
  const double span = std::max(hi_x - lo_x, hi_y - lo_y) * (1 + 1e-9) + 1e-12;
  const int cells = std::clamp(int(std::sqrt(double(segments.size()))), 1, 4096);
  const double cell = span / cells;
  auto cell_of = [&](double v, double lo) { return std::clamp(int((v - lo) / cell), 0, cells - 1); };
  std::vector<std::vector<uint32_t>> buckets(size_t(cells) * size_t(cells));
  for (uint32_t s = 0; s < segments.size(); ++s) {
    const auto [a, b] = end_points(segments[s]);
    for (int y = cell_of(std::min(a.y, b.y), lo_y); y <= cell_of(std::max(a.y, b.y), lo_y); ++y)
      for (int x = cell_of(std::min(a.x, b.x), lo_x); x <= cell_of(std::max(a.x, b.x), lo_x); ++x)
        buckets[size_t(y) * cells + x].push_back(s);
  }
  size_t self_meetings = 0, mutual_meetings = 0;
  for (int cy = 0; cy < cells; ++cy) {
    for (int cx = 0; cx < cells; ++cx) {
      const auto& bucket = buckets[size_t(cy) * cells + cx];
      for (size_t p = 0; p < bucket.size(); ++p) {
        for (size_t q = p + 1; q < bucket.size(); ++q) {
          const Segment& s = segments[bucket[p]];
          const Segment& t = segments[bucket[q]];
          const auto [a, b] = end_points(s);
          const auto [c, d] = end_points(t);
          // Each pair once: in the lowest cell both boxes cover.
          const int x0 = std::max(cell_of(std::min(a.x, b.x), lo_x), cell_of(std::min(c.x, d.x), lo_x));
          const int y0 = std::max(cell_of(std::min(a.y, b.y), lo_y), cell_of(std::min(c.y, d.y), lo_y));
          if (x0 != cx || y0 != cy) continue;
          if (s.loop == t.loop) {
            const size_t n = contours[s.loop].size();
            const bool adjacent = (s.index + 1) % n == t.index || (t.index + 1) % n == s.index;
            if (adjacent) {
              // Consecutive segments meet at their shared vertex only, unless they fold back.
              const Vec2d& shared = (s.index + 1) % n == t.index ? b : a;
              const Vec2d& u = (s.index + 1) % n == t.index ? a : b;
              const Vec2d& v = (s.index + 1) % n == t.index ? d : c;
              if (orientation(u, shared, v) == 0 && (u.x - shared.x) * (v.x - shared.x) + (u.y - shared.y) * (v.y - shared.y) > 0)
                ++self_meetings;
              continue;
            }
            if (segments_meet(a, b, c, d)) ++self_meetings;
          } else if (segments_meet(a, b, c, d)) {
            ++mutual_meetings;
          }
        }
      }
    }
  }
  if (self_meetings) {
    check.simple = false;
    check.problems.push_back(std::to_string(self_meetings) + " places where a contour meets itself");
  }
  if (mutual_meetings) {
    check.disjoint = false;
    check.problems.push_back(std::to_string(mutual_meetings) + " places where two contours meet");
  }
  if (!check.simple || !check.disjoint) return check;
  // Nesting depth: crossings of a ray towards +x from each loop's first vertex, by rows.
  std::vector<std::vector<uint32_t>> rows(static_cast<size_t>(cells));
  for (uint32_t s = 0; s < segments.size(); ++s) {
    const auto [a, b] = end_points(segments[s]);
    for (int y = cell_of(std::min(a.y, b.y), lo_y); y <= cell_of(std::max(a.y, b.y), lo_y); ++y) rows[size_t(y)].push_back(s);
  }
  size_t misoriented = 0;
  for (size_t l = 0; l < contours.size(); ++l) {
    const Vec2d& p = contours[l][0];
    size_t crossings = 0;
    for (uint32_t s : rows[size_t(cell_of(p.y, lo_y))]) {
      if (segments[s].loop == l) continue;
      const auto [a, b] = end_points(segments[s]);
      if ((a.y > p.y) == (b.y > p.y)) continue;
      const double x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
      if (x > p.x) ++crossings;
    }
    const bool outer = crossings % 2 == 0;
    if ((signed_area(contours[l]) > 0) != outer) ++misoriented;
  }
  if (misoriented) {
    check.oriented = false;
    check.problems.push_back(std::to_string(misoriented) +
                             " contours wound the wrong way (outer boundaries counter-clockwise, holes clockwise)");
  }
  return check;
}

}  // namespace lacuna
