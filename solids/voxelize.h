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

// A horizontal slab lo_mm <= z <= hi_mm: what a streamed run builds at a time.
struct ZSlab {
  double lo_mm = 0, hi_mm = 0;
};

// The union of every piece as one level set: analytic pieces rasterized together into one grid,
// closed meshes and extruded regions converted and united with it. Validates first. With a slab,
// the union intersected with it (see PrimitiveRasterizer::clip_z): the analytic pieces make no leaf
// beyond the slab's band; closed meshes and regions are converted whole, then clipped.
// `meshes`, when given, is voxelize_meshes() of the same set, made once for every slab.
Volume voxelize(const GeometrySet& set, const VolumeOptions& options, const ZSlab* slab = nullptr,
                const Volume* meshes = nullptr);

// The set's closed meshes and extruded regions alone, converted whole and united (empty if it has
// none): what a streamed run converts once and clips for every slab.
Volume voxelize_meshes(const GeometrySet& set, const VolumeOptions& options);

// The volume intersected with the slab, max(d, lo - z, z - hi): a closed solid again, equal to the
// volume bit for bit at least a band inside the slab.
Volume clip_to_slab(const Volume& volume, const ZSlab& slab);

}  // namespace lacuna
