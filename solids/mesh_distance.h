// Distances between triangle meshes, for measuring what simplification does to a surface.
#pragma once

#include "geometry.h"

namespace lacuna {

// The one-sided Hausdorff distance from `from` to `to`, sampled: the largest distance from a
// sample of `from` (every vertex and centroid, and in triangles larger than `fine_area_mm2` when it
// is positive, the edge midpoints and a barycentric grid of steps 1/4) to the nearest point of the
// triangles of `to` (exact point-triangle distances, nearest triangles found through a grid).
// A lower bound of the true one-sided distance that converges to it as the samples get denser.
// `where` (optional) receives the sample of `from` that is farthest.
double sampled_hausdorff_mm(const TriMesh& from, const TriMesh& to, double fine_area_mm2 = 0, Vec3d* where = nullptr);

// The distance from p to the closed triangle abc.
double point_triangle_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

}  // namespace lacuna
