#include "geometry.h"

namespace lacuna {

Box3 bounding_box(const TriMesh& mesh) {
  Box3 box;
  for (const Vec3d& p : mesh.positions_mm) box.expand(p);
  return box;
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
