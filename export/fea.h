// Tetrahedral meshes in the formats finite-element tools read: Gmsh .msh (4.1 and 2.2),
// Abaqus/CalculiX .inp (C3D4 or C3D10), VTK .vtu, Medit .mesh.
#pragma once

#include <string>

#include "geometry.h"

namespace lacuna {

enum class FeaFormat { kMsh, kInp, kVtu, kMedit };

// The format named by a file's extension (.msh .inp .vtu .mesh); throws InvalidInput otherwise.
FeaFormat fea_format_from_path(const std::string& path);
bool is_fea_path(const std::string& path);

struct FeaWriteOptions {
  bool msh_version_2 = false;  // Gmsh 2.2 instead of 4.1
  bool quadratic = false;      // .inp: C3D10 with mid-side nodes instead of C3D4
  // .inp node sets: how far a node may lie from a plane of the bounding box (mm); the larger of
  // this and 1e-6 of the box's size. A simplified surface is flat only to its deviation.
  double node_set_tolerance_mm = 0;
};

// Writes the mesh. Node and element numbers start at 1. The .inp holds *NODE, *ELEMENT (one
// element set per material region: EREGION<i>, and EALL), and node sets NXMIN, NXMAX, NYMIN,
// NYMAX, NZMIN, NZMAX of the nodes on the bounding box's planes (within 1e-6 of its size, or
// options.node_set_tolerance_mm when that is larger).
// Deterministic. Throws IoError on failure.
void write_fea(const std::string& path, FeaFormat format, const TetMesh& mesh, const FeaWriteOptions& options = {});

}  // namespace lacuna
