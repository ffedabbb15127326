// Memory refusals shared by the pipeline's stages (not part of its public API).
#pragma once

#include <cstdint>
#include <string>

#include "solids/volume.h"

namespace lacuna {
namespace detail {

// A number with `digits` significant digits, for messages.
std::string fixed(double v, int digits);

// The message refusing `what`, which needs `need` bytes beyond the budget, naming a voxel size that
// would fit (memory goes with the surface resolved, about 1 / voxel size^2).
std::string refusal(const std::string& what, uint64_t need, uint64_t budget, const VolumeOptions& vopt);

// Throws ResourceLimit before meshing a level set whose mesh and checks would not fit next to what is
// in use now.
// simplify_mm: the smallest deviation the mesh is simplified to (0: the plain mesh).
void require_mesh_memory(const Volume& v, uint64_t budget, const std::string& what, const VolumeOptions& vopt,
                         double simplify_mm = 0);

// Throws ResourceLimit before extracting a level set's surface to distance it again (an offset, a
// shell, an infill's skin) when that surface would not fit next to what is in use now.
void require_surface_memory(const Volume& v, uint64_t budget, const std::string& what, const VolumeOptions& vopt);

}  // namespace detail
}  // namespace lacuna
