// Explicit repairs of imported hulls, each asked for by name, never applied silently.
#pragma once

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

struct RepairOptions {
  double weld_mm = 0;        // > 0: merge vertices closer than this, drop collapsed and duplicate faces
  bool reorient = false;     // make faces consistently and outwardly oriented
  double close_gaps_mm = 0;  // > 0: close cracks and holes up to this width (morphological closing)
};

// Applies the repairs asked for, in the order weld, reorient, close gaps; `voxel_size_mm` is the
// resolution of the closing. The result may still be invalid; check it.
TriMesh repair_mesh(const TriMesh& mesh, const RepairOptions& options, double voxel_size_mm);

}  // namespace lacuna
