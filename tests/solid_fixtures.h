// Level sets of simple solids that several test files build their cases from.
#pragma once

#include "geometry.h"
#include "solids/voxelize.h"

namespace lacuna {
namespace test {

// The axis-aligned box [lo, hi] at voxel size h (exact distance function, band of 3 voxels).
inline Volume box(const Vec3d& lo, const Vec3d& hi, double h) {
  GeometrySet set;
  Shape s;
  s.kind = Shape::Kind::kBox;
  s.center_mm = (lo + hi) * 0.5;
  s.half_size_mm = (hi - lo) * 0.5;
  set.shapes.push_back(s);
  return voxelize(set, VolumeOptions{h, 3.0});
}

}  // namespace test
}  // namespace lacuna
