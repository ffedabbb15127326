#include "solids/mesh_distance.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <tuple>
#include <vector>

namespace lacuna {
namespace {

// The triangles of a mesh listed in the cells of a uniform grid their boxes overlap.
class TriangleGrid {
 public:
  TriangleGrid(const TriMesh& mesh, const Box3& bounds) : mesh_(mesh) {
    // Cells about twice the typical triangle's width (long thin triangles span several), grown
    // until the lists hold at most 16 entries per triangle and the grid 8 cells per triangle.
    double area = 0;
    for (const auto& t : mesh.triangles) {
      const Vec3d &a = mesh.positions_mm[t[0]], &b = mesh.positions_mm[t[1]], &c = mesh.positions_mm[t[2]];
      area += 0.5 * norm(cross(b - a, c - a));
    }
    const size_t nt = std::max<size_t>(1, mesh.triangles.size());
    const double span = std::max({bounds.size().x, bounds.size().y, bounds.size().z, 1e-9});
    cell_ = std::max(2 * std::sqrt(area / double(nt)), span / 1024);
    origin_ = bounds.min;
    for (;;) {
      double cells = 1;
      for (int k = 0; k < 3; ++k) {
        dims_[k] = int64_t(bounds.size()[k] / cell_) + 1;
        cells *= double(dims_[k]);
      }
      double entries = 0;
      if (cells <= 8.0 * double(nt) + 4096)
        for (const auto& t : mesh.triangles) {
          Box3 b;
          for (uint32_t v : t) b.expand(mesh.positions_mm[v]);
          entries += double(coord(b.max.x, 0) - coord(b.min.x, 0) + 1) * double(coord(b.max.y, 1) - coord(b.min.y, 1) + 1) *
                     double(coord(b.max.z, 2) - coord(b.min.z, 2) + 1);
        }
      if (cells <= 8.0 * double(nt) + 4096 && entries <= 16.0 * double(nt) + 4096) break;
      cell_ *= 1.25;
    }
    lists_.resize(size_t(dims_[0] * dims_[1] * dims_[2]));
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      Box3 b;
      for (uint32_t v : mesh.triangles[t]) b.expand(mesh.positions_mm[v]);
      const int64_t x0 = coord(b.min.x, 0), x1 = coord(b.max.x, 0), y0 = coord(b.min.y, 1), y1 = coord(b.max.y, 1),
                    z0 = coord(b.min.z, 2), z1 = coord(b.max.z, 2);
      for (int64_t x = x0; x <= x1; ++x)
        for (int64_t y = y0; y <= y1; ++y)
          for (int64_t z = z0; z <= z1; ++z) lists_[size_t((x * dims_[1] + y) * dims_[2] + z)].push_back(t);
    }
  }

  // Distance from p (inside the bounds) to the nearest triangle: rings of cells around p's cell
  // until no unvisited cell can hold anything nearer.
  double nearest(const Vec3d& p) const {
    const int64_t c[3] = {coord(p.x, 0), coord(p.y, 1), coord(p.z, 2)};
    double best = HUGE_VAL;
    const int64_t max_ring = std::max({dims_[0], dims_[1], dims_[2]});
    for (int64_t r = 0; r <= max_ring; ++r) {
      for (int64_t x = c[0] - r; x <= c[0] + r; ++x) {
        if (x < 0 || x >= dims_[0]) continue;
        for (int64_t y = c[1] - r; y <= c[1] + r; ++y) {
          if (y < 0 || y >= dims_[1]) continue;
          for (int64_t z = c[2] - r; z <= c[2] + r; ++z) {
            if (z < 0 || z >= dims_[2]) continue;
            if (std::max({std::abs(x - c[0]), std::abs(y - c[1]), std::abs(z - c[2])}) != r) continue;
            for (uint32_t t : lists_[size_t((x * dims_[1] + y) * dims_[2] + z)]) {
              const auto& tri = mesh_.triangles[t];
              best = std::min(best, point_triangle_distance(p, mesh_.positions_mm[tri[0]], mesh_.positions_mm[tri[1]],
                                                            mesh_.positions_mm[tri[2]]));
            }
          }
        }
      }
      if (best <= double(r) * cell_) break;
    }
    return best;
  }

 private:
  int64_t coord(double v, int k) const {
    return std::clamp<int64_t>(int64_t(std::floor((v - origin_[k]) / cell_)), 0, dims_[k] - 1);
  }

  const TriMesh& mesh_;
  Vec3d origin_;
  double cell_ = 1;
  int64_t dims_[3] = {1, 1, 1};
  std::vector<std::vector<uint32_t>> lists_;
};

}  // namespace

double point_triangle_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  return std::sqrt(point_triangle_distance2(p, a, b, c));
}

double squared_limit(double d) {
  double s = d * d;
  while (s > 0 && std::sqrt(s) > d) s = std::nextafter(s, 0.0);
  while (std::sqrt(std::nextafter(s, HUGE_VAL)) <= d) s = std::nextafter(s, HUGE_VAL);
  return s;
}

double sampled_hausdorff_mm(const TriMesh& from, const TriMesh& to, double fine_area_mm2, Vec3d* where) {
  if (from.triangles.empty() || to.triangles.empty()) return from.triangles.empty() ? 0 : HUGE_VAL;
  Box3 bounds;
  for (const Vec3d& p : from.positions_mm) bounds.expand(p);
  for (const Vec3d& p : to.positions_mm) bounds.expand(p);
  const TriangleGrid grid(to, bounds);
  struct Worst {
    double distance = 0;
    Vec3d at;
  };
  auto better = [](const Worst& x, const Worst& y) {
    if (x.distance != y.distance) return x.distance > y.distance ? x : y;
    return std::tie(x.at.x, x.at.y, x.at.z) < std::tie(y.at.x, y.at.y, y.at.z) ? x : y;
  };
  // Every vertex once (at the first triangle that names it), every centroid; edge midpoints and a
  // barycentric grid only in triangles larger than fine_area_mm2.
  std::vector<uint32_t> first_use(from.positions_mm.size(), UINT32_MAX);
  for (uint32_t f = 0; f < from.triangles.size(); ++f)
    for (uint32_t v : from.triangles[f])
      if (first_use[v] == UINT32_MAX) first_use[v] = f;
  const Worst worst = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, from.triangles.size(), 256), Worst{},
      [&](const tbb::blocked_range<size_t>& range, Worst w) {
        auto sample = [&](const Vec3d& p) { w = better(w, Worst{grid.nearest(p), p}); };
        for (size_t f = range.begin(); f != range.end(); ++f) {
          const auto& t = from.triangles[f];
          const Vec3d &a = from.positions_mm[t[0]], &b = from.positions_mm[t[1]], &c = from.positions_mm[t[2]];
          for (uint32_t v : t)
            if (first_use[v] == f) sample(from.positions_mm[v]);
          sample((a + b + c) / 3.0);
          if (fine_area_mm2 > 0 && 0.5 * norm(cross(b - a, c - a)) > fine_area_mm2) {
            for (const Vec3d& p : {(a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5}) sample(p);
            for (int i = 0; i <= 4; ++i)
              for (int j = 0; i + j <= 4; ++j) sample(a + (b - a) * (i / 4.0) + (c - a) * (j / 4.0));
          }
        }
        return w;
      },
      better);
  if (where) *where = worst.at;
  return worst.distance;
}

}  // namespace lacuna
