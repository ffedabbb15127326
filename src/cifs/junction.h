// A junction between two CIFS tensor surfaces of different natures (../shared/spec/cifs.md): A = U x Va
// ends at v = 1 on a curve of U's nature, B = U x Vb starts at v = 0 on another; the junction J = U x W
// joins A's end curve to B's start curve, of A's nature next to A and of B's next to B.
//
// W is a curve automaton on the merged control polygon of A and B (per row of U: A's ka points, then
// B's kb points) with three transitions from its state j:
//   T0: j -> Va (a piece of A's nature),  T1: j -> j (the junction again),  T2: j -> Vb (B's nature),
// so J has 2 x 3 transformations when U has two. On the chord from P = A's end to R = B's start:
//   - T0's piece runs from P to P' = (1 - r) P + r R, A's polygon with its chord mapped onto [P, P'] and
//     its deviation from the chord scaled by `amplitude` x the ratio of the chords;
//   - T2's piece, B's likewise, from R' = (1 - r) R + r P to R;
//   - T1 is derived from them: the homothety of ratio 1 - 2r towards the middle (P + R) / 2, so the
//     middle piece starts where T0's ends (T1 P = P') and ends where T2's starts (T1 R = R').
// The junction's v = 0 border is then A's v = 1 border exactly (T0 maps Va's start to P), its v = 1
// border B's v = 0 border, at every level. The constraints fix T0's and T2's end points only and
// T1 entirely, so no extra control points are needed: the merged polygon is J's.
#pragma once

#include <Eigen/Dense>

#include "cifs/automaton.h"

namespace lacuna {
namespace cifs {

struct JunctionOptions {
  double ratio = 1.0 / 3;  // share of the chord each side's first piece takes, in (0, 0.5)
  double amplitude = 1;    // the side pieces' deviation from their chords, relative to a similar copy
  bool sides = false;      // the system's attractor: the junction alone, or A, J and B together
};

// A surface given as its two factors and its control net (3 x ku*kv, index iu * kv + iv).
struct TensorSurface {
  Automaton u, v;
  Eigen::MatrixXd control_points;
};

// The junction of `a` and `b` (both non-rational, sharing the automaton U within 1e-12). With
// `sides`, an initial state whose first symbol picks A (0 .. |Va| - 1), J (|Va| .. |Va| + 2) or B, so
// that level L shows the three surfaces each at level L. Throws InvalidInput when U differs, a factor
// is not a curve, or an option is out of range.
Cifs junction(const TensorSurface& a, const TensorSurface& b, const JunctionOptions& options);

// Whether two automata are the same within `tolerance` (states, primitives, transitions, matrices).
bool same_automaton(const Automaton& x, const Automaton& y, double tolerance);

}  // namespace cifs
}  // namespace lacuna
