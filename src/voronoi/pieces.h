// Pieces of a fractal Voronoi partition placed in space as plain geometry: tiles as convex cells (2D
// polygons extruded into prisms) and the walls between colours thickened into a foam.
#pragma once

#include <array>
#include <vector>

#include "geometry.h"
#include "voronoi/walls.h"

namespace lacuna {
namespace voronoi {

// Where the unit torus of a partition lies in space.
struct TorusPlacement {
  int dimension = 3;     // 2: the partition lies in the plane z = origin_mm.z
  double period_mm = 1;  // mm per unit of the torus
  Vec3d origin_mm;       // where the torus point 0 goes

  // The point (x, y, z) of the torus (its periods unwrapped) in mm; z is ignored in 2D.
  Vec3d to_mm(double x, double y, double z) const;
};

// Adds a convex piece (torus units): a 2D polygon (faces[0], counter-clockwise) as a prism [0, height_mm]
// along z, a 3D piece's faces as they are.
void add_piece(const TorusPlacement& part, const std::vector<std::vector<Point3>>& faces, double height_mm,
               GeometrySet& geometry);

// Adds every wall of the periodic network in the periods [lo, hi) of each axis, thickened to wall_mm: 3D
// walls as a shell of their triangles, 2D walls as prisms of height_mm (each reaching half a width past its
// ends, so walls meeting at a point cover it).
void add_foam(const TorusPlacement& part, const Walls& walls, const std::array<int, 3>& lo, const std::array<int, 3>& hi,
              double wall_mm, double height_mm, GeometrySet& geometry);

}  // namespace voronoi
}  // namespace lacuna
