// A tree-like support for a CIFS tensor surface (../shared/spec/cifs.md): a branching volume
// subdivision whose branches end on the surface's pieces, level by level, and whose root stands on
// the build plate.
//
// A branch over a piece of the surface in state q is a hexahedron: its top the piece's four corners,
// its bottom a small quad (four base control points). Its control points are the piece's (k_q) and the
// four base points, so one automaton carries both: a branch subdivides, for every transition of the
// surface (symbol s, matrix M), into a child branch whose top is the sub-piece (M on the surface's
// points) and whose base is the fork quad, the parent's base scaled by `shrink` about the fork point
// (`fork` of the way from the base's centre to the piece's centre); and on one more symbol into its
// trunk, the frustum from its base to the fork quad, which stays as it is at every later level (an
// identity loop). Level L is the trunks of levels 0 .. L - 1 and the 4^L branches (for a 2 x 2
// surface) whose tops are the surface's level-L pieces exactly.
#pragma once

#include "cifs/automaton.h"
#include "geometry.h"

namespace lacuna {
namespace cifs {

struct SupportOptions {
  Vec3d base_center_mm{0, 0, 0};  // the root's base centre (on the build plate)
  double base_size_mm = 0;        // the root base's size; 0: a quarter of the surface's
  double fork = 0.5;              // the fork point's share of the way from a base to its piece, (0, 1)
  double shrink = 0.5;            // the child base (fork quad) against its parent's base, (0, 1]
};

// The support tree of `surface` (a tensor surface: every state a quad with four corners). The root's
// base is the surface's outline (its corners about their centre) projected on the plane z =
// base_center.z, scaled to base_size_mm and centred at base_center_mm, so that every branch keeps its
// piece's corner order. Throws InvalidInput for a surface that is not a tensor surface, a base
// above the surface, or options out of range.
Cifs support_tree(const Cifs& surface, const SupportOptions& options);

}  // namespace cifs
}  // namespace lacuna
