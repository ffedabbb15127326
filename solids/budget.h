// Memory estimates made before anything large is allocated, so a job that cannot fit is refused
// with a voxel size that would fit instead of crashing. The figures per voxel and per triangle
// are measured (see README, "Memory model").
#pragma once

#include <cstdint>

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

struct MemoryEstimate {
  double surface_area_mm2 = 0;  // upper bound of the surface to be resolved
  uint64_t active_voxels = 0;   // narrow-band voxels
  uint64_t triangles = 0;       // triangles of the extracted surface
  uint64_t grid_bytes = 0;      // level set plus rasterization work space
  uint64_t mesh_bytes = 0;      // extracting, writing, re-reading and checking the surface
  uint64_t surface_bytes = 0;   // the surface alone, extracted to be distanced again (offsets, shells, skins)
};

// Narrow-band voxels a surface of this area needs, capped by the voxels of the box it lies in
// (a dense union cannot have more band than its box has voxels).
uint64_t band_voxels(double surface_area_mm2, const Box3& box, const VolumeOptions& options);

// Estimate for a level set with this many active voxels, and for meshing and checking it.
// The share of the plain mesh's memory a compact mesh needs: it is simplified block by block as
// it is extracted, so the full marching-tetrahedra mesh never exists. Measured on the capsule walk
// at a fifth of a voxel (bench/run_capsules.sh): the peak of extraction, simplification, re-reading
// and checking is 55-65 bytes per extracted triangle against 160-180 for the plain mesh; 0.45 keeps
// a margin for deviations down to a tenth of a voxel, which keep more triangles. 1 below that.
double compact_mesh_share(double simplify_mm, double voxel_size_mm);

MemoryEstimate estimate_from_voxels(uint64_t active_voxels, const VolumeOptions& options);

// Estimate for voxelizing a geometry set: its level set, the rasterizer's work space, its mesh.
MemoryEstimate estimate_voxelize(const GeometrySet& set, const VolumeOptions& options);

}  // namespace lacuna
