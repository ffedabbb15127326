// Tessellation of a CIFS at a level: every accepted word of that length gives one piece
// P * T_w1 * ... * T_wl * K, streamed in lexicographic order of the words.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <vector>

#include "cifs/automaton.h"
#include "geometry.h"

namespace lacuna {
namespace cifs {

struct Piece {
  const std::vector<int>* word;  // the symbols, length = level
  int state;                     // the state the word ends in
  const Eigen::Matrix3Xd* vertices;  // the primitive's vertices placed in space (mm)
};

// Number of accepted words of length `level` (without enumerating them).
uint64_t count_pieces(const Automaton& automaton, int level);

// Calls `visit` for every piece of the level, in lexicographic order of the words; the piece's
// references are valid during the call only. Depth-first: memory grows with the level, not with
// the number of pieces. The CIFS must have complete primitives (complete_primitives()).
void for_each_piece(const Cifs& cifs, int level, const std::function<void(const Piece&)>& visit);

// The curve pieces of the level joined into polylines: consecutive pieces that meet (end of one
// = start of the next within 1e-9 of the drawing's size) share the vertex; gaps start a new one.
std::vector<std::vector<Vec3d>> tessellate_curves(const Cifs& cifs, int level);

// The surface pieces of the level as one triangle mesh (quads split in two, polygons fanned),
// vertices welded where pieces meet (within 1e-9 of the drawing's size).
TriMesh tessellate_surface(const Cifs& cifs, int level);

// The volume pieces of the level as convex cells, in batches of at most `batch_cells`, so a level
// with millions of pieces streams. All volume states must share one primitive kind.
void tessellate_cells(const Cifs& cifs, int level, size_t batch_cells,
                      const std::function<void(const ConvexCells&)>& sink);

// The faces (outward for the standard vertex order, indices into the primitive's vertices) of a
// tetrahedron, hexahedron or the state's own polyhedron.
std::vector<std::vector<int>> primitive_faces(const State& state);

}  // namespace cifs
}  // namespace lacuna
