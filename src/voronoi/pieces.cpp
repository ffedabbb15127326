#include "voronoi/pieces.h"

#include <cmath>
#include <utility>

namespace lacuna {
namespace voronoi {

Vec3d TorusPlacement::to_mm(double x, double y, double z) const {
  return origin_mm + Vec3d{x * period_mm, y * period_mm, dimension == 3 ? z * period_mm : 0.0};
}

void add_piece(const TorusPlacement& part, const std::vector<std::vector<Point3>>& faces, double height_mm,
               GeometrySet& geometry) {
  ConvexCells cell;
  if (part.dimension == 2) {
    const auto& loop = faces[0];
    const size_t k = loop.size();
    cell.corners_per_cell = int(2 * k);
    for (const Point3& p : loop) cell.corners_mm.push_back(part.to_mm(p[0], p[1], 0));
    for (const Point3& p : loop) cell.corners_mm.push_back(part.to_mm(p[0], p[1], 0) + Vec3d{0, 0, height_mm});
    std::vector<int> bottom, top;
    for (size_t i = 0; i < k; ++i) {
      bottom.push_back(int(i));
      top.push_back(int(k + i));
      cell.faces.push_back({int(i), int((i + 1) % k), int(k + (i + 1) % k), int(k + i)});
    }
    cell.faces.push_back(bottom);
    cell.faces.push_back(top);
  } else {
    int corners = 0;
    for (const auto& face : faces) {
      std::vector<int> loop;
      for (const Point3& p : face) {
        cell.corners_mm.push_back(part.to_mm(p[0], p[1], p[2]));
        loop.push_back(corners++);
      }
      cell.faces.push_back(std::move(loop));
    }
    cell.corners_per_cell = corners;
  }
  geometry.cells.push_back(std::move(cell));
}

// The foam: every wall of the periodic network, thickened, in the periods [lo, hi) of each axis (torus units).
void add_foam(const TorusPlacement& part, const Walls& walls, const std::array<int, 3>& lo, const std::array<int, 3>& hi,
              double wall_mm, double height_mm, GeometrySet& geometry) {
  if (part.dimension == 3) {
    ThickSurface surface;
    surface.thickness_mm = wall_mm;
    surface.surface = wall_triangles(walls, part.period_mm, part.origin_mm, lo, hi);
    if (!surface.surface.triangles.empty()) geometry.surfaces.push_back(std::move(surface));
    return;
  }
  // A 2D wall segment as a convex prism of the wall's width reaching half a width past each end, so that
  // it covers the disk of the wall's width around both ends (where walls meet).
  const double half = wall_mm / 2 / part.period_mm;  // torus units
  for (int ty = lo[1]; ty < hi[1]; ++ty)
    for (int tx = lo[0]; tx < hi[0]; ++tx)
      for (const auto& facet : walls.facets) {
        const Point3 &a = facet[0], &b = facet[1];
        const double dx = b[0] - a[0], dy = b[1] - a[1], length = std::hypot(dx, dy);
        const double ux = dx / length * half, uy = dy / length * half;  // along the wall, half a width
        const double x0 = a[0] + tx - ux, y0 = a[1] + ty - uy, x1 = b[0] + tx + ux, y1 = b[1] + ty + uy;
        add_piece(part, {{{x0 + uy, y0 - ux, 0}, {x1 + uy, y1 - ux, 0}, {x1 - uy, y1 + ux, 0}, {x0 - uy, y0 + ux, 0}}},
                  height_mm, geometry);
      }
}

}  // namespace voronoi
}  // namespace lacuna
