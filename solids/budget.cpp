#include "solids/budget.h"

#include <algorithm>
#include <cmath>

#include "solids/voxelize.h"

namespace lacuna {
namespace {

// Measured on spheres, tori, capsule chains and plates (see the budget test):
constexpr double kTrianglesPerVoxelFace = 9.5;   // marching tetrahedra: triangles per (area / h^2)
constexpr double kLeafBytesPerVoxelFace = 64.0;  // grid leaves (8^3 x 4 B, partly filled) per (area / h^2)
constexpr double kMeshBytesPerTriangle = 420.0;  // extraction + STL/3MF re-read + CGAL checks, peak
constexpr double kPairBytes = 16.0;              // one (leaf, primitive) pair while rasterizing

double voxel_faces(double area_mm2, double h) { return area_mm2 / (h * h); }

}  // namespace

uint64_t estimate_mesh_bytes(uint64_t triangles) { return uint64_t(double(triangles) * kMeshBytesPerTriangle); }

MemoryEstimate estimate_from_area(double surface_area_mm2, const VolumeOptions& options) {
  MemoryEstimate e;
  const double h = options.voxel_size_mm;
  const double faces = voxel_faces(surface_area_mm2, h);
  e.surface_area_mm2 = surface_area_mm2;
  e.active_voxels = uint64_t(std::min(faces * 2.0 * options.half_band_voxels, 1e19));
  e.triangles = uint64_t(std::min(faces * kTrianglesPerVoxelFace, 1e19));
  e.grid_bytes = uint64_t(std::min(faces * kLeafBytesPerVoxelFace * options.half_band_voxels / 3.0, 1e19));
  e.mesh_bytes = uint64_t(std::min(double(e.triangles) * kMeshBytesPerTriangle, 1e19));
  return e;
}

MemoryEstimate estimate_voxelize(const GeometrySet& set, const VolumeOptions& options) {
  MemoryEstimate e = estimate_from_area(surface_area_bound_mm2(set), options);
  // Rasterization work space: one pair per leaf in each primitive's box (an upper bound).
  const double leaf = 8.0 * options.voxel_size_mm, band = options.voxel_size_mm * options.half_band_voxels;
  auto leaves = [&](const Vec3d& size) {
    return ((size.x + 2 * band) / leaf + 1.0) * ((size.y + 2 * band) / leaf + 1.0) * ((size.z + 2 * band) / leaf + 1.0);
  };
  double pairs = 0;
  for (const Tube& tube : set.tubes.tubes)
    for (size_t i = 0; i + 1 < std::max<size_t>(tube.points_mm.size(), 2); ++i) {
      Box3 box;
      double r = *std::max_element(tube.radii_mm.begin(), tube.radii_mm.end());
      const Vec3d& a = tube.points_mm[i];
      const Vec3d& b = tube.points_mm[std::min(i + 1, tube.points_mm.size() - 1)];
      box.expand(a);
      box.expand(b);
      pairs += leaves(box.size() + Vec3d{2 * r, 2 * r, 2 * r});
    }
  for (size_t i = 0; i < set.spheres.centers_mm.size(); ++i) {
    double r = set.spheres.radii_mm.size() == 1 ? set.spheres.radii_mm[0] : set.spheres.radii_mm[i];
    pairs += leaves(Vec3d{2 * r, 2 * r, 2 * r});
  }
  for (const Shape& s : set.shapes) {
    GeometrySet one;
    one.shapes.push_back(s);
    pairs += leaves(bounding_box(one).size());
  }
  for (const ThickSurface& ts : set.surfaces) pairs += double(ts.surface.triangles.size()) * 8.0;
  e.grid_bytes += uint64_t(std::min(pairs * kPairBytes, 1e19));
  return e;
}

}  // namespace lacuna
