// Tetrahedral meshes for finite elements, by TetGen, from a checked closed surface.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "geometry.h"

namespace lacuna {

struct TetOptions {
  double max_radius_edge_ratio = 0;  // quality bound (TetGen -q), > 1; 0: no quality refinement
  double min_dihedral_deg = 0;       // with a quality bound: smallest dihedral angle to aim for; 0: TetGen's
  double max_tet_volume_mm3 = 0;     // largest tetrahedron (TetGen -a); 0: unbounded
  bool preserve_surface = true;      // no points added on the boundary (TetGen -Y), so the tets' faces there are
                                     // the surface's triangles; only without bounds: TetGen 1.5 refines
                                     // nothing under -Y (with bounds, added points still lie on the surface)
  double time_limit_s = 600;         // TetGen runs in a child process, stopped after this long
  uint64_t max_memory_bytes = 0;     // the child may allocate this much (RLIMIT_AS); 0: no limit of its own
};

// The TetGen switch string for the options: always a piecewise linear complex, zero-based,
// quiet ("pzQ"); "Y" to preserve the surface when nothing is refined; "q<ratio>/<angle>";
// "a<volume>"; "A" with regions.
// Throws InvalidInput for a ratio <= 1 or non-positive volumes.
std::string tetgen_switches(const TetOptions& options, bool regions);

// Tetrahedralizes the solid a closed, outward-oriented surface bounds. Cavities (components
// nested inside an odd number of others) stay empty. `region_seeds` (optional) gives a point per
// material region; tetrahedra get the index of their region's seed. Throws InvalidInput when
// TetGen rejects the surface (self-intersections, features too small), ResourceLimit when it runs
// out of memory (its budget) or time. The child process dies with the one that started it.
TetMesh tetrahedralize(const TriMesh& surface, const TetOptions& options,
                       const std::vector<Vec3d>& region_seeds = {});

struct TetReport {
  uint64_t nodes = 0;
  uint64_t tets = 0;
  double volume_mm3 = 0;
  double min_tet_volume_mm3 = 0;
  double max_tet_volume_mm3 = 0;
  double min_dihedral_deg = 0;
  double max_dihedral_deg = 0;
  uint64_t inverted_tets = 0;                 // non-positive volume
  std::vector<double> ratio_bins;             // radius-edge ratio histogram: upper bounds of the bins
  std::vector<uint64_t> ratio_counts;         // tets per bin (last bin: above the last bound)
};

// Counts, volumes, dihedral angles and the radius-edge ratio (circumradius / shortest edge)
// histogram of a tetrahedral mesh.
TetReport tet_report(const TetMesh& mesh);

}  // namespace lacuna
