// Connected components of a triangle mesh (through shared vertices) and their measures.
#pragma once

#include <cstdint>
#include <vector>

#include "geometry.h"

namespace lacuna {

struct MeshComponent {
  std::vector<uint32_t> triangles;  // indices into the mesh's triangles
  double signed_volume_mm3 = 0;     // > 0 for an outward shell, < 0 for a cavity's
  double area_mm2 = 0;
  Vec3d centroid_mm;                // of the enclosed volume (of the vertices when it is zero)
  Box3 box;
};

// The components in order of their first triangle.
std::vector<MeshComponent> mesh_components(const TriMesh& mesh);

// Removes the cavity shells (components of negative volume) enclosing less than `max_volume_mm3`,
// which fills those pockets, and the vertices left unused; returns how many were removed. A
// level set meshed at voxel size h cannot resolve a pocket below h^3: where three tubes meet,
// marching tetrahedra can close one off from sub-voxel sign changes.
size_t fill_small_cavities(TriMesh& mesh, double max_volume_mm3);

// Removes the specks: outward shells (components of non-negative volume) enclosing less than
// `max_volume_mm3`. Below h^3 they are what is left of sub-voxel features (a sliver a drain hole
// cut off, a wall's corner clipped by a hull): unprintable dust, not part of the design.
size_t remove_small_specks(TriMesh& mesh, double max_volume_mm3);

}  // namespace lacuna
