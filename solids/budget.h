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
  uint64_t active_voxels = 0;   // narrow-band voxels of the result
  uint64_t triangles = 0;       // triangles of its extracted surface
  uint64_t grid_bytes = 0;      // level set plus rasterization work space
  uint64_t mesh_bytes = 0;      // extraction, writing, re-reading and checking the mesh
  uint64_t bytes() const { return grid_bytes > mesh_bytes ? grid_bytes : mesh_bytes; }
};

// Estimate for voxelizing a geometry set.
MemoryEstimate estimate_voxelize(const GeometrySet& set, const VolumeOptions& options);

// Estimate for a level set (and its mesh) whose surface has the given area.
MemoryEstimate estimate_from_area(double surface_area_mm2, const VolumeOptions& options);

// Bytes for meshing and checking a surface of `triangles` triangles.
uint64_t estimate_mesh_bytes(uint64_t triangles);

}  // namespace lacuna
