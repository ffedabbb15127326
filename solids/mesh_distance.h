// Distances between triangle meshes, for measuring what simplification does to a surface.
#pragma once

#include <algorithm>
#include <cmath>

#include "geometry.h"

namespace lacuna {

// The one-sided Hausdorff distance from `from` to `to`, sampled: the largest distance from a
// sample of `from` (every vertex and centroid, and in triangles larger than `fine_area_mm2` when it
// is positive, the edge midpoints and a barycentric grid of steps 1/4) to the nearest point of the
// triangles of `to` (exact point-triangle distances, nearest triangles found through a grid).
// A lower bound of the true one-sided distance that converges to it as the samples get denser.
// `where` (optional) receives the sample of `from` that is farthest.
double sampled_hausdorff_mm(const TriMesh& from, const TriMesh& to, double fine_area_mm2 = 0, Vec3d* where = nullptr);

// The squared distance from p to the closed triangle abc (Ericson, Real-Time Collision Detection,
// 5.1.5: the closest point by Voronoi regions). Inline: the simplifier's deviation tests call it
// tens of millions of times.
inline double point_triangle_distance2(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  auto norm2 = [](const Vec3d& v) { return dot(v, v); };
  const Vec3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return norm2(p - a);
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return norm2(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return norm2(p - (a + ab * (d1 / (d1 - d3))));
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return norm2(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return norm2(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return norm2(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const double denominator = va + vb + vc;
  if (!(denominator > 0))  // degenerate: the nearest of its edges
    return std::min(
        {point_segment_distance2(p, a, b), point_segment_distance2(p, b, c), point_segment_distance2(p, c, a)});
  const double v = vb / denominator, w = vc / denominator;
  return norm2(p - (a + ab * v + ac * w));
}

// The distance from p to the closed triangle abc: the square root of point_triangle_distance2.
double point_triangle_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

// The largest squared distance s whose square root, as std::sqrt rounds it, is at most d (d >= 0
// finite): `point_triangle_distance2(...) <= s` decides exactly what `point_triangle_distance(...)
// <= d` does, without the root (the root is monotonic and correctly rounded).
double squared_limit(double d);

}  // namespace lacuna
