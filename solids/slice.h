// A level set cut by horizontal planes: its signed distance sampled on a layer's pixel grid, and the
// box its surface fills, for layers (src/layers/layers.h) without a mesh.
#pragma once

#include <vector>

#include "layers/layers.h"
#include "solids/volume.h"

namespace lacuna {

// The signed distance (mm, negative inside) at the centre of every pixel of `grid` in the plane
// z = z_mm, row j = 0 first, trilinear between voxel centres (beyond the narrow band: +band outside,
// -band inside). A value within 1e-5 voxel of 0 (a point on the surface, where rounding picks the
// sign: a horizontal face on the layer's plane) reads -1e-5 voxel: on the surface counts as inside,
// everywhere alike. Rows in parallel; identical for any thread count.
std::vector<float> sample_layer(const Volume& volume, double z_mm, const LayerGrid& grid);

// The box of the solid (mm): the union of the balls the inside voxels' distances guarantee to be
// solid, so exact where the surface is flat or convex and within the interpolation's error (a
// small fraction of a voxel) elsewhere. Empty for an empty volume. With a range, only the voxels
// whose centres lie in z_lo_mm <= z <= z_hi_mm count (a slab of a streamed run).
Box3 solid_box(const Volume& volume);
Box3 solid_box(const Volume& volume, double z_lo_mm, double z_hi_mm);

}  // namespace lacuna
