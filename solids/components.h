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

// What remove_small_shells removed.
struct SmallShells {
  size_t cavities = 0;  // cavity shells (negative volume), so their pockets are filled
  size_t specks = 0;    // outward shells
};

// Removes the shells enclosing less than `max_volume_mm3` and the vertices left unused. A level
// set meshed at voxel size h resolves nothing below h^3: a cavity shell that small is a pocket
// marching tetrahedra closed off from sub-voxel sign changes (where three tubes meet); an outward
// shell that small is what is left of a sub-voxel feature (a sliver a drain hole cut off, a
// wall's corner clipped by a hull): unprintable dust, not part of the design.
SmallShells remove_small_shells(TriMesh& mesh, double max_volume_mm3);

// The separate bodies of a closed mesh enclosing less than `max_volume_mm3`: outward shells (positive
// volume) whose bounding box holds no other shell's box, so that nothing is nested in them (a body
// with a cavity, or one inside another's cavity's box, is never one). In order of their first triangle.
std::vector<MeshComponent> loose_pieces(const TriMesh& mesh, double max_volume_mm3);

// The mesh without the given components' triangles and the vertices left unused (the others keep
// their order).
void remove_components(TriMesh& mesh, const std::vector<MeshComponent>& components);

}  // namespace lacuna
