// Draco outputs: quantized finely enough that no vertex moves further than asked, written, decoded
// again from the file and checked like every other mesh; where quantization would join vertices
// the mesh keeps apart or make triangles cross, the grid is refined and the file written again.
#pragma once

#include <cstdint>
#include <string>

#include "geometry.h"
#include "solids/check.h"

namespace lacuna {

struct DracoFigures {
  int quantization_bits = 0;
  double max_move_mm = 0;         // the bound on any decoded vertex's displacement at those bits
  uint64_t file_bytes = 0;
  uint64_t binary_stl_bytes = 0;  // the same mesh as a binary STL, for the compression ratio
  int refinements = 0;            // grids refused because the decoded mesh failed its checks
};

struct DracoOutput {
  DracoFigures figures;
  MeshCheckReport check;  // of the mesh decoded from the file written
};

// Writes `mesh` to `path` with the coarsest grid that keeps every vertex within `max_move_mm`,
// refining it (two bits at a time, up to 30) while the decoded file fails its checks. The result's
// check is that of the last file written: invalid when no grid helped (the caller removes it).
// Throws InvalidInput when even 30 bits cannot reach `max_move_mm`.
DracoOutput write_checked_draco(const std::string& path, const TriMesh& mesh, double max_move_mm,
                                uint64_t max_memory_bytes);

}  // namespace lacuna
