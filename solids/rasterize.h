// Direct rasterization of analytic primitives (tubes, spheres, boxes, cylinders, tori, thickened
// triangles) into one narrow-band level set, from their exact distance functions, in parallel.
// OpenVDB 10 has no capsule rasterizer (LevelSetTubes arrived in 12.1), and going through a tube
// triangle soup and meshToLevelSet is ~20x slower and less accurate.
#pragma once

#include <memory>

#include "geometry.h"
#include "solids/volume.h"

namespace lacuna {

// Number of distance primitives (round cones, spheres, shapes, triangles) in the set's analytic
// part (tubes, spheres, shapes, surfaces).
size_t primitive_count(const GeometrySet& set);

// Builds one level set from primitives handed over in batches: each batch is rasterized and
// merged into the grid as a minimum, so a generator with millions of pieces never holds them all.
class PrimitiveRasterizer {
 public:
  explicit PrimitiveRasterizer(const VolumeOptions& options);
  ~PrimitiveRasterizer();
  PrimitiveRasterizer(const PrimitiveRasterizer&) = delete;
  PrimitiveRasterizer& operator=(const PrimitiveRasterizer&) = delete;

  // Keeps only the slab lo_mm <= z <= hi_mm of what is added (before the first add): the level set
  // becomes that of the pieces' union intersected with the slab, max(d, lo - z, z - hi), and no leaf
  // beyond the slab's band is made. Values at least a band inside the slab equal the unclipped ones
  // bit for bit. hi_mm - lo_mm must exceed two bands.
  void clip_z(double lo_mm, double hi_mm);
  // Adds the batch's analytic pieces (tubes, spheres, shapes, surfaces, cells); others ignored.
  void add(const GeometrySet& batch);
  // The level set of everything added; the rasterizer starts over empty.
  Volume finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Rasterizes the union of the set's analytic part into one level set with exact distances in
// the narrow band; closed meshes and regions are ignored here (see voxelize()). The set must
// have passed validate(). Deterministic for any number of threads.
Volume rasterize_primitives(const GeometrySet& set, const VolumeOptions& options);

}  // namespace lacuna
