// Narrow-band signed distance volumes (negative inside) and the operations on them: CSG,
// offsets, shells, and conversion of closed meshes. The grid type stays hidden.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "geometry.h"

namespace lacuna {

struct VolumeOptions {
  double voxel_size_mm = 0.1;     // edge of a voxel; voxel centres lie at integer multiples
  double half_band_voxels = 3.0;  // narrow band on each side of the surface, in voxels (>= 2)
};

// A solid as a narrow-band level set. Copies share the immutable grid; every operation returns
// a new volume and leaves its arguments untouched.
class Volume {
 public:
  struct Impl;

  Volume();
  explicit Volume(std::shared_ptr<const Impl> impl);

  const VolumeOptions& options() const;
  double voxel_size_mm() const { return options().voxel_size_mm; }
  double band_mm() const { return options().voxel_size_mm * options().half_band_voxels; }
  uint64_t active_voxel_count() const;
  uint64_t leaf_count() const;
  uint64_t memory_bytes() const;
  // Bounding box of the voxels inside or near the surface, in mm; empty for an empty volume.
  Box3 bounding_box() const;
  bool empty() const { return active_voxel_count() == 0; }
  // The signed distance at a point (mm), trilinearly interpolated; +band outside the band.
  double distance_at(const Vec3d& p_mm) const;
  // Volume of the solid in mm^3 counted voxel by voxel with a linear ramp across the band
  // (accurate to about a voxel layer; the mesh volume is the precise figure).
  double voxel_volume_mm3() const;

  const Impl& impl() const { return *impl_; }

 private:
  std::shared_ptr<const Impl> impl_;
};

// Closed mesh to a level set (mesh to signed distance). The mesh must be closed; orientation
// does not matter. Throws InvalidInput for an empty mesh.
Volume mesh_to_volume(const TriMesh& closed_mesh, const VolumeOptions& options);

// a ∪ b, a ∖ b, a ∩ b. Throws InvalidInput when the voxel sizes differ.
Volume unite(const Volume& a, const Volume& b);
Volume subtract(const Volume& a, const Volume& b);
Volume intersect(const Volume& a, const Volume& b);

// Grows (distance > 0) or shrinks (distance < 0) the solid by a Euclidean distance in mm.
Volume offset(const Volume& v, double distance_mm);

// offset(v, d) for every d, from one extraction and one distance computation over the band all of
// them need (an infill's skin and core share it). OpenVDB widens a band by propagating nearest
// triangles, so the distances can differ from a separate offset's by a fraction of a voxel.
std::vector<Volume> offsets(const Volume& v, const std::vector<double>& distances_mm);

// offsets() of mesh_to_volume(closed_mesh), taken from the mesh itself: distances to its own
// triangles rather than to the level set's surface (which follows them within the interpolation's
// error), and no surface to extract. The mesh must have no cavity (no inward shell); throws
// InvalidInput for one that has, or that has no triangles.
std::vector<Volume> mesh_offsets(const TriMesh& closed_mesh, const VolumeOptions& options,
                                 const std::vector<double>& distances_mm);

// The solid minus its inward offset: a hollow part with walls of the given thickness (mm > 0).
Volume shell(const Volume& v, double thickness_mm);
// The same with that inward offset made already (offsets() of v, or mesh_offsets() of its mesh).
Volume shell(const Volume& v, double thickness_mm, const Volume& inward_offset);

}  // namespace lacuna
