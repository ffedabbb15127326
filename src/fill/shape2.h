// Internal to the fill stage: placed motifs as world-space shapes, their exact overlap tests with a gap,
// and a hierarchical hash grid that finds the neighbours of a trial position in about constant time.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <unordered_map>
#include <string>
#include <vector>

#include "errors.h"
#include "fill/fill.h"
#include "geometry.h"

namespace lacuna {
namespace fill {
namespace detail {

inline double dot2(const Vec2d& a, const Vec2d& b) { return a.x * b.x + a.y * b.y; }
inline double length2(const Vec2d& v) { return std::hypot(v.x, v.y); }

// A motif placed in the plane: a circle, or a polygon with its vertices in millimetres.
struct Shape2 {
  Vec2d center;               // the motif's centroid
  double radius = 0;          // the circle's radius, or the polygon's bounding radius about its centroid
  bool circle = true;
  bool convex = true;
  std::vector<Vec2d> points;  // polygon vertices, counter-clockwise
  Vec2d interior;             // a point strictly inside
};

// The motif under its placement: centre + scale * R(angle) * (x, +-y).
Shape2 place(const Motif2& motif, const Placement2& placement);

// Crossing-number test (either orientation); points on the outline go either way.
bool point_in_polygon(const std::vector<Vec2d>& polygon, const Vec2d& p);
// The distance from p to the outline of the polygon.
double outline_distance(const std::vector<Vec2d>& polygon, const Vec2d& p);
// Whether some edge of one polygon meets some edge of the other.
bool outlines_intersect(const std::vector<Vec2d>& a, const std::vector<Vec2d>& b);
// min over the vertices of each polygon of the distance to the other's outline: the distance between two
// outlines that do not meet (it is attained at a vertex of one of them).
double vertex_outline_distance(const std::vector<Vec2d>& a, const std::vector<Vec2d>& b);

// Whether the shapes come closer than gap_mm (overlapping shapes are at distance 0); with gap 0, touching
// shapes do not overlap, except that non-convex polygons whose outlines touch count as overlapping.
bool overlap(const Shape2& a, const Shape2& b, double gap_mm);

// The stop reason of a fill whose motif i found no room: "max_trials: <what> i could not be placed in T trials".
std::string trials_reason(const char* what, size_t i, size_t trials);

// Throws InvalidInput unless c > 1, N > 1, both gaps >= 0 and trials >= 1.
void check_law(double c, double N, double gap, double boundary_gap, size_t trials, size_t count);

// The area (volume) rule, shared by every fill: motif i takes the fraction 1 / (zeta(c, N) (N + i)^c) of
// `measure`. For i = 0 .. max_count - 1 it stops with `min_reason` once that part is below `min_part`;
// otherwise it calls trial(i, part) up to max_trials times, until one places the motif (returns true), and
// stops with trials_reason(what, ...) when none did. Sets stop_reason ("max_count" when every motif was
// placed) and returns the fraction of `measure` placed.
template <class Trial>
double place_by_rule(double measure, double c, double N, size_t max_count, double min_part, const char* min_reason,
                     size_t max_trials, const char* what, std::string& stop_reason, Trial&& trial) {
  if (max_count > kMaxFillCount)
    throw InvalidInput("fill: count must be at most 10 000 000, got " + std::to_string(max_count));
  const double zeta = hurwitz_zeta(c, N);
  double filled = 0;
  stop_reason = "max_count";
  for (size_t i = 0; i < max_count; ++i) {
    const double fraction = 1 / (zeta * std::pow(N + double(i), c));
    const double part = measure * fraction;
    if (part < min_part) {
      stop_reason = min_reason;
      return filled;
    }
    bool placed = false;
    for (size_t t = 0; t < max_trials && !placed; ++t) placed = trial(i, part);
    if (!placed) {
      stop_reason = trials_reason(what, i, max_trials);
      return filled;
    }
    filled += fraction;
  }
  return filled;
}

// A hierarchical uniform grid: an entry of radius r lives in the level whose cell size h = 2^L is the
// smallest power of two >= r, in the one cell holding its centre; a query visits, on each level, the cells
// within reach + h of the query point (or the level's whole list, when that is shorter). Since motifs only
// get smaller, nearly all entries live on levels coarser than the query's reach, where it visits a few cells.
template <int D>
class GridIndex {
 public:
  using Point = std::array<double, D>;

  void insert(int id, const Point& center, double radius) {
    const int level = level_of(radius);
    Level& lv = levels_[level];
    lv.cell = std::ldexp(1.0, level);
    lv.ids.push_back(id);
    if (size_t(id) >= entries_.size()) entries_.resize(size_t(id) + 1);
    entries_[size_t(id)] = {center, radius};
    std::array<int64_t, D> cell;
    for (int k = 0; k < D; ++k) cell[k] = int64_t(std::floor(center[k] / lv.cell));
    lv.buckets[key(cell)].push_back(id);
  }

  // Calls hit(id) for every entry whose centre lies within reach + its radius of p, until hit returns
  // true; returns whether one did.
  template <class Hit>
  bool any(const Point& p, double reach, Hit&& hit) const {
    for (const auto& entry : levels_) {
      const Level& lv = entry.second;
      std::array<int64_t, D> lo, hi;
      double cells = 1;
      for (int k = 0; k < D; ++k) {
        lo[k] = int64_t(std::floor((p[k] - reach - lv.cell) / lv.cell));
        hi[k] = int64_t(std::floor((p[k] + reach + lv.cell) / lv.cell));
        cells *= double(hi[k] - lo[k] + 1);
      }
      if (cells > double(lv.ids.size())) {
        for (int id : lv.ids)
          if (near(id, p, reach) && hit(id)) return true;
        continue;
      }
      std::array<int64_t, D> c = lo;
      while (true) {
        const auto it = lv.buckets.find(key(c));
        if (it != lv.buckets.end())
          for (int id : it->second)
            if (in_cell(id, c, lv.cell) && near(id, p, reach) && hit(id)) return true;
        int k = 0;
        while (k < D && ++c[k] > hi[k]) c[k] = lo[k], ++k;
        if (k == D) break;
      }
    }
    return false;
  }

 private:
  struct Level {
    double cell = 1;
    std::vector<int> ids;
    std::unordered_map<uint64_t, std::vector<int>> buckets;
  };
  struct Entry {
    Point center;
    double radius;
  };

  static int level_of(double radius) {
    const double l = radius > 0 ? std::ceil(std::log2(radius)) : -900.0;
    return int(std::clamp(l, -900.0, 900.0));
  }
  static uint64_t key(const std::array<int64_t, D>& c) {
    static constexpr uint64_t kMix[3] = {0x9E3779B97F4A7C15ull, 0xC2B2AE3D27D4EB4Full, 0x165667B19E3779F9ull};
    uint64_t h = 0;
    for (int k = 0; k < D; ++k) h ^= uint64_t(c[k]) * kMix[k];
    return h;
  }
  // Different cells may share a bucket; an entry is seen only from its own cell.
  bool in_cell(int id, const std::array<int64_t, D>& c, double cell) const {
    const Entry& e = entries_[size_t(id)];
    for (int k = 0; k < D; ++k)
      if (int64_t(std::floor(e.center[k] / cell)) != c[k]) return false;
    return true;
  }
  bool near(int id, const Point& p, double reach) const {
    const Entry& e = entries_[size_t(id)];
    double d2 = 0;
    for (int k = 0; k < D; ++k) d2 += (e.center[k] - p[k]) * (e.center[k] - p[k]);
    const double r = reach + e.radius;
    return d2 < r * r;
  }

  std::map<int, Level> levels_;
  std::vector<Entry> entries_;  // by id
};

}  // namespace detail
}  // namespace fill
}  // namespace lacuna
