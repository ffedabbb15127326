// Direct rasterization of analytic primitives (tubes, spheres, boxes, cylinders, tori, thickened
// triangles) into one narrow-band level set, from their exact distance functions, in parallel.
// OpenVDB 10 has no capsule rasterizer (LevelSetTubes arrived in 12.1), and going through a tube
// triangle soup and meshToLevelSet is ~20x slower and less accurate.
#pragma once

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

// Number of distance primitives (round cones, spheres, shapes, triangles) in the set's analytic
// part (tubes, spheres, shapes, surfaces).
size_t primitive_count(const GeometrySet& set);

// Rasterizes the union of the set's analytic part into one level set with exact distances in
// the narrow band; closed meshes and regions are ignored here (see voxelize()). The set must
// have passed validate(). Deterministic for any number of threads.
Volume rasterize_primitives(const GeometrySet& set, const VolumeOptions& options);

}  // namespace lacuna
