#include "solids/budget.h"

#include <algorithm>
#include <cmath>

#include "solids/voxelize.h"

namespace lacuna {
namespace {

// Measured (README, "Memory model"): marching tetrahedra give 1.5-1.6 triangles per active voxel
// of a 3-voxel band; the leaves hold about 11 bytes per active voxel; extracting, re-reading and
// checking (CGAL surface mesh and box tree) peak at about 160 bytes per triangle.
constexpr double kTrianglesPerActiveVoxel = 1.6;
constexpr double kGridBytesPerActiveVoxel = 12.0;
constexpr double kMeshBytesPerTriangle = 180.0;
// An offset's surface: the triangle mesh (12 bytes of corners, half a 24-byte vertex per triangle)
// and the extraction's crossing maps; its distance band is counted as a wider level set. Checked
// against the peak memory of bench/infill_60mm.json (README, "Streaming").
constexpr double kSurfaceBytesPerTriangle = 72.0;
constexpr double kPairBytes = 16.0;  // one (leaf, primitive) pair while rasterizing

uint64_t saturate(double v) { return v >= 1.8e19 ? uint64_t(1.8e19) : uint64_t(std::max(v, 0.0)); }

}  // namespace

uint64_t band_voxels(double surface_area_mm2, const Box3& box, const VolumeOptions& options) {
  const double h = options.voxel_size_mm;
  double from_area = surface_area_mm2 / (h * h) * 2.0 * options.half_band_voxels;
  if (box.empty()) return saturate(from_area);
  const double pad = 2 * h * options.half_band_voxels;
  Vec3d size = box.size();
  double from_box = (size.x + pad) / h * ((size.y + pad) / h) * ((size.z + pad) / h);
  return saturate(std::min(from_area, from_box));
}

double compact_mesh_share(double simplify_mm, double voxel_size_mm) {
  return simplify_mm >= 0.1 * voxel_size_mm ? 0.45 : 1.0;
}

MemoryEstimate estimate_from_voxels(uint64_t active_voxels, const VolumeOptions& options) {
  (void)options;
  MemoryEstimate e;
  e.active_voxels = active_voxels;
  e.triangles = saturate(double(active_voxels) * kTrianglesPerActiveVoxel);
  e.grid_bytes = saturate(double(active_voxels) * kGridBytesPerActiveVoxel);
  e.mesh_bytes = saturate(double(e.triangles) * kMeshBytesPerTriangle);
  e.surface_bytes = saturate(double(e.triangles) * kSurfaceBytesPerTriangle);
  return e;
}

MemoryEstimate estimate_voxelize(const GeometrySet& set, const VolumeOptions& options) {
  const double area = surface_area_bound_mm2(set);
  MemoryEstimate e = estimate_from_voxels(band_voxels(area, bounding_box(set), options), options);
  e.surface_area_mm2 = area;
  // Rasterization work space: one pair per leaf in each primitive's box (an upper bound).
  const double leaf = 8.0 * options.voxel_size_mm, band = options.voxel_size_mm * options.half_band_voxels;
  auto leaves = [&](const Vec3d& size) {
    return ((size.x + 2 * band) / leaf + 1.0) * ((size.y + 2 * band) / leaf + 1.0) * ((size.z + 2 * band) / leaf + 1.0);
  };
  double pairs = 0;
  for (const Tube& tube : set.tubes.tubes) {
    const double r = *std::max_element(tube.radii_mm.begin(), tube.radii_mm.end());
    for (size_t i = 0; i + 1 < std::max<size_t>(tube.points_mm.size(), 2); ++i) {
      Box3 box;
      box.expand(tube.points_mm[i]);
      box.expand(tube.points_mm[std::min(i + 1, tube.points_mm.size() - 1)]);
      pairs += leaves(box.size() + Vec3d{2 * r, 2 * r, 2 * r});
    }
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
  for (const ConvexCells& cells : set.cells) {
    const size_t m = size_t(cells.corners_per_cell);
    for (size_t c = 0; c < cells.size(); ++c) {
      Box3 box;
      for (size_t i = 0; i < m; ++i) box.expand(cells.corners_mm[c * m + i]);
      pairs += leaves(box.size());
    }
  }
  e.grid_bytes += saturate(pairs * kPairBytes);
  return e;
}

}  // namespace lacuna
