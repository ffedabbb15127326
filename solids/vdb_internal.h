// Private to solids/*.cpp: the OpenVDB grid behind Volume. Never include from a public header.
#pragma once

#include <openvdb/openvdb.h>

#include "solids/volume.h"

namespace lacuna {

struct Volume::Impl {
  openvdb::FloatGrid::Ptr grid;
  VolumeOptions options;
};

// Calls openvdb::initialize() once per process.
void ensure_openvdb_initialized();

// A transform with voxel centres at integer multiples of the voxel size.
openvdb::math::Transform::Ptr make_transform(double voxel_size_mm);

// An empty level-set grid with background = band (mm).
openvdb::FloatGrid::Ptr make_level_set_grid(const VolumeOptions& options);

Volume wrap_grid(openvdb::FloatGrid::Ptr grid, const VolumeOptions& options);

}  // namespace lacuna
