// A geometry set (what generators and recipe inputs produce) into one level set.
#pragma once

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

// Checks the set (finite coordinates, positive radii and sizes, matching radius counts, indices
// in range, closed meshes for solids) and throws InvalidInput naming the first offending piece.
void validate(const GeometrySet& set);

// The largest surface area (mm^2) the union can have: the sum of the pieces' areas, with the
// overlaps of consecutive tube segments removed. Used to estimate memory before voxelizing.
double surface_area_bound_mm2(const GeometrySet& set);

// Bounding box of the union (mm).
Box3 bounding_box(const GeometrySet& set);

// The union of every piece as one level set: analytic pieces rasterized together into one grid,
// closed meshes and extruded regions converted and united with it. Validates first.
Volume voxelize(const GeometrySet& set, const VolumeOptions& options);

}  // namespace lacuna
