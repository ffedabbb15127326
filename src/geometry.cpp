#include "geometry.h"

#include <algorithm>

namespace lacuna {

Box3 bounding_box(const TriMesh& mesh) {
  Box3 box;
  for (const Vec3d& p : mesh.positions_mm) box.expand(p);
  return box;
}

double signed_area(const std::vector<Vec2d>& polygon) {
  double a = 0;
  for (size_t i = 0, n = polygon.size(); i < n; ++i) a += cross2(polygon[i], polygon[(i + 1) % n]);
  return a / 2;
}

bool segments_intersect(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d) {
  auto orient = [](const Vec2d& p, const Vec2d& q, const Vec2d& r) {
    const double v = cross2(q - p, r - p);
    return (v > 0) - (v < 0);
  };
  auto on = [](const Vec2d& p, const Vec2d& q, const Vec2d& r) {  // r in the box of pq (r collinear with it)
    return std::min(p.x, q.x) <= r.x && r.x <= std::max(p.x, q.x) && std::min(p.y, q.y) <= r.y &&
           r.y <= std::max(p.y, q.y);
  };
  const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  // A proper crossing needs strictly opposite signs on both sides; a zero means an end point lies on the other
  // segment's line, and counts only within that segment's box (rounded signs of nearly collinear segments
  // would otherwise report crossings far from either segment).
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && on(a, b, c)) || (o2 == 0 && on(a, b, d)) || (o3 == 0 && on(c, d, a)) ||
         (o4 == 0 && on(c, d, b));
}

double signed_volume(const TriMesh& mesh) {
  // Sum of tetrahedra from the box centre: the centre keeps the terms small for parts far from
  // the origin. Long double keeps a 10^7-triangle sum accurate to ~1e-12 relative.
  Box3 box = bounding_box(mesh);
  Vec3d c = box.empty() ? Vec3d{} : (box.min + box.max) * 0.5;
  long double six_v = 0;
  for (const auto& t : mesh.triangles) {
    Vec3d a = mesh.positions_mm[t[0]] - c, b = mesh.positions_mm[t[1]] - c,
          d = mesh.positions_mm[t[2]] - c;
    six_v += dot(a, cross(b, d));
  }
  return static_cast<double>(six_v / 6.0L);
}

double surface_area(const TriMesh& mesh) {
  long double area2 = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3d& a = mesh.positions_mm[t[0]];
    area2 += norm(cross(mesh.positions_mm[t[1]] - a, mesh.positions_mm[t[2]] - a));
  }
  return static_cast<double>(area2 / 2.0L);
}

}  // namespace lacuna
