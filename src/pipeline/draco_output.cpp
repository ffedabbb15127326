#include "pipeline/draco_output.h"


#include <algorithm>

#include "errors.h"
#include "export/draco.h"
#include "export/mesh_io.h"
#include "export/output_files.h"

namespace lacuna {

DracoOutput write_checked_draco(const std::string& path, const TriMesh& mesh, double max_move_mm,
                                uint64_t max_memory_bytes) {
  const int coarsest = draco_quantization_bits(mesh, max_move_mm);
  if (coarsest == 0)
    throw InvalidInput(path + ": Draco cannot keep vertices within " + message_number(max_move_mm) +
                       " mm of a part this large (30 quantization bits move them up to " +
                       message_number(draco_move_bound_mm(mesh, kMaxDracoBits)) + " mm)");
  DracoOutput out;
  out.figures.binary_stl_bytes = 84 + 50 * uint64_t(mesh.triangles.size());
  for (int bits = coarsest;; bits = std::min(bits + 2, kMaxDracoBits)) {
    const std::string bytes = encode_draco(mesh, bits);
    write_whole_file(path, bytes);
    ReadOptions read;
    read.max_memory_bytes = max_memory_bytes;
    const TriMesh back = read_mesh(path, MeshFormat::kDrc, read);
    out.figures.quantization_bits = bits;
    out.figures.max_move_mm = draco_move_bound_mm(mesh, bits);
    out.figures.file_bytes = bytes.size();
    out.check = check_mesh(back);
    // Draco keeps every vertex and triangle of a closed manifold mesh; anything else is a failure.
    const bool same_counts = back.triangles.size() == mesh.triangles.size() &&
                             back.positions_mm.size() == mesh.positions_mm.size();
    if (out.check.valid() && same_counts) return out;
    if (bits == kMaxDracoBits) {
      if (!same_counts) throw InternalError(path + ": Draco changed the number of vertices or triangles");
      return out;
    }
    ++out.figures.refinements;
  }
}

}  // namespace lacuna
