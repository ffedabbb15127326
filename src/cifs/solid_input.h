// CIFS attractors as solids: curves as tubes, surfaces as shells, volumes as cells, any of
// them as the edges of their pieces; pieces streamed to the solid stage in batches.
#pragma once

#include <cstddef>

#include "cifs/automaton.h"
#include "geometry.h"

namespace lacuna {
namespace cifs {

struct SolidOptions {
  enum class As { kDefault, kTubes, kShell, kCells, kEdges };
  As as = As::kDefault;         // default: curves -> tubes, surfaces -> shell, volumes -> cells
  double radius_mm = 0;         // tubes and edges
  double thickness_mm = 0;      // shells
  size_t batch_pieces = 65536;  // pieces per batch handed to the rasterizer
  double voxel_size_mm = 0;     // when set, levels whose pieces are far below a voxel are refused
};

// The geometry of level `level` as a stream of batches (nothing is generated until it is read).
// Throws InvalidInput when the options do not fit the system's primitives, or when (with a voxel
// size) the level's pieces are under an eighth of a voxel and a lower level would give the same voxels.
GeometrySet attractor_geometry(const Cifs& cifs, int level, const SolidOptions& options);

// The system scaled uniformly and moved so that its attractor's box fits `box`, centred.
Cifs fit_to_box(const Cifs& cifs, const Box3& box);

}  // namespace cifs
}  // namespace lacuna
