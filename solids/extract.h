// Surface extraction from a volume: marching tetrahedra over the narrow band. The result is
// closed, edge- and vertex-manifold, outward-oriented and free of self-intersections by
// construction (see README, "Why marching tetrahedra").
#pragma once

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

struct ExtractOptions {
  // Crossing points are kept at least this fraction of an edge away from grid points, so no
  // triangle degenerates and neighbouring cells keep a margin after float32 rounding.
  double min_edge_fraction = 0.01;
};

// Triangulates the zero level set of the volume. Vertices are in mm, triangles counter-clockwise
// seen from outside. Deterministic for any number of threads.
TriMesh extract_surface(const Volume& volume, const ExtractOptions& options = {});

}  // namespace lacuna
