// Exact geometric predicates on double coordinates (CGAL's filtered predicates inside, never in
// this header): orientation, collinearity, and whether two triangles of a mesh meet anywhere
// other than in the vertices and edge they share. Used by the simplifier's guards and the checks.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "geometry.h"

namespace lacuna::exact {

// Sign of the orientation of d with respect to the plane through a, b, c: +1 when d lies on
// the side (b - a) x (c - a) points to (CGAL's POSITIVE), -1 on the other side, 0 coplanar.
// The determinant is evaluated in doubles first and trusted when it exceeds Shewchuk's static
// error bound (o3derrboundA); otherwise CGAL decides exactly.
int orient3d(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d);
int orient3d_exact(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d);

inline int orient3d(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d) {
  // Shewchuk's orient3d(a, b, c, d) = det[a - d, b - d, c - d], which is minus CGAL's orientation.
  const double adx = a.x - d.x, bdx = b.x - d.x, cdx = c.x - d.x;
  const double ady = a.y - d.y, bdy = b.y - d.y, cdy = c.y - d.y;
  const double adz = a.z - d.z, bdz = b.z - d.z, cdz = c.z - d.z;
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const double permanent = (std::fabs(bdxcdy) + std::fabs(cdxbdy)) * std::fabs(adz) +
                           (std::fabs(cdxady) + std::fabs(adxcdy)) * std::fabs(bdz) +
                           (std::fabs(adxbdy) + std::fabs(bdxady)) * std::fabs(cdz);
  constexpr double kEpsilon = 1.1102230246251565e-16;  // 2^-53
  constexpr double kBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;
  const double bound = kBound * permanent;
  if (bound < 1e-280) return orient3d_exact(a, b, c, d);  // the bound itself may have underflowed
  if (det > bound) return -1;
  if (-det > bound) return 1;
  return orient3d_exact(a, b, c, d);
}

// Sign of the orientation of the 2D points (a, b, c): +1 counter-clockwise, -1 clockwise, 0 collinear.
// Doubles first, trusted beyond Shewchuk's static bound (ccwerrboundA); otherwise CGAL decides.
int orient2d(double ax, double ay, double bx, double by, double cx, double cy);
int orient2d_exact(double ax, double ay, double bx, double by, double cx, double cy);

inline int orient2d(double ax, double ay, double bx, double by, double cx, double cy) {
  const double left = (ax - cx) * (by - cy), right = (ay - cy) * (bx - cx);
  const double det = left - right;
  constexpr double kEpsilon = 1.1102230246251565e-16;  // 2^-53
  constexpr double kBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
  const double bound = kBound * (std::fabs(left) + std::fabs(right));
  if (bound < 1e-280) return orient2d_exact(ax, ay, bx, by, cx, cy);
  if (det > bound) return 1;
  if (-det > bound) return -1;
  return orient2d_exact(ax, ay, bx, by, cx, cy);
}

// Whether a, b, c lie on one line (a repeated point counts as collinear): exactly when their
// projections onto the three coordinate planes are all collinear.
inline bool collinear(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  return orient2d(a.x, a.y, b.x, b.y, c.x, c.y) == 0 && orient2d(a.y, a.z, b.y, b.z, c.y, c.z) == 0 &&
         orient2d(a.z, a.x, b.z, b.x, c.z, c.x) == 0;
}

// Whether the closed segment pq and the closed triangle abc share a point.
bool segment_meets_triangle(const Vec3d& p, const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c);

// Whether the closed triangles abc and def share a point.
bool triangles_meet(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& d, const Vec3d& e,
                    const Vec3d& f);

// Whether the mesh triangles t and u (vertex indices into `positions`) intersect anywhere other
// than in what they share by index: nothing, one vertex, or one edge. Triangles with all three
// vertices in common always count as intersecting. Neither triangle may be degenerate.
bool faces_intersect(const Vec3d* positions, const std::array<uint32_t, 3>& t, const std::array<uint32_t, 3>& u);

// The same for triangles given by their corners and vertex ids (ids only decide what is shared).
bool faces_intersect(const std::array<Vec3d, 3>& tp, const std::array<uint32_t, 3>& t,
                     const std::array<Vec3d, 3>& up, const std::array<uint32_t, 3>& u);

}  // namespace lacuna::exact
