// Surface decimation to a stated maximum deviation (OpenMesh's decimater), for lighter files and
// for surfaces that tetrahedral meshers can handle. The result must be checked again: decimation
// keeps the topology but not, by construction, the absence of self-intersections.
#pragma once

#include "geometry.h"

namespace lacuna {

struct DecimateOptions {
  double max_deviation_mm = 0.01;     // bound on the distance of every vertex to the original faces'
                                      // planes merged into it (quadric error <= deviation^2)
  double max_normal_change_deg = 30;  // no collapse turns a face normal further than this
};

// Collapses edges, cheapest quadric error first, while the quadric error stays below the
// deviation squared and no face normal turns by more than the limit. Throws InvalidInput for a non-positive
// deviation or a mesh that is not an edge-manifold triangle mesh.
TriMesh decimate(const TriMesh& mesh, const DecimateOptions& options);

}  // namespace lacuna
