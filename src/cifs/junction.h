// A junction between two CIFS tensor surfaces of different natures (../shared/spec/cifs.md): A = Ua x Va
// ends at v = 1 on a curve of Ua's nature, B = Ub x Vb starts at v = 0 on another; the junction J joins
// A's end curve to B's start curve, of A's nature next to A and of B's next to B.
//
// J's control points are A's and B's merged (per point of u: A's ka points, then B's kb points) and its
// v direction W has three transitions from its state j:
//   T0: j -> Va (a piece of A's nature),  T1: j -> j (the junction again),  T2: j -> Vb (B's nature),
// so J has 2 x 3 transformations when u has two. T0's piece runs from A's end P to P', A's polygon with
// its chord mapped onto [P, P'] and its deviation from the chord scaled by `amplitude` x the ratio of the
// chords; T2's piece, B's likewise, from R' to B's start R; T1 is derived so that the middle piece starts
// where T0's ends (T1 P = P') and ends where T2's starts (T1 R = R'). J's v = 0 border is then A's v = 1
// border exactly (T0 maps Va's start to P), its v = 1 border B's v = 0 border, at every level.
//   - One u automaton (Ua = Ub): P' = (1 - r) P + r R, R' = (1 - r) R + r P, and T1 is the homothety of
//     ratio 1 - 2r towards (P + R) / 2; the constraints fix T0's and T2's end points and all of T1, so no
//     control point is added and J = U x W.
//   - Two u automata (the borders may share one control polygon): every row of J's net follows the u
//     subdivision of its own nature, so no map may mix A's rows with B's (the u pieces of one nature
//     would otherwise part at J's inner seams). The constraints then leave no point where the natures
//     meet, so two free control points per point of u are added: F_A and F_B, the straight seam S from
//     X (the middle of the two borders' start points) to Y (of their end points) drawn in A's nature and
//     in B's (each u automaton must draw a straight segment with equal pieces: linear precision). T1 is
//     the homothety of ratio 1 - 2r towards F_A on A's rows and towards F_B on B's, P' = T1 P, R' = T1 R:
//     J's pieces of A's nature shrink from A's border towards S, those of B's from B's border, and both
//     meet on S piece by piece.
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

// The junction of `a` and `b` (both non-rational; their u automata the same within 1e-12, or of equal
// sizes and both with linear precision). With
// `sides`, an initial state whose first symbol picks A (0 .. |Va| - 1), J (|Va| .. |Va| + 2) or B, so
// that level L shows the three surfaces each at level L. Throws InvalidInput when the u automata cannot
// meet, a factor is not a curve, the sides leave nothing to join, or an option is out of range.
Cifs junction(const TensorSurface& a, const TensorSurface& b, const JunctionOptions& options);

// Whether two automata are the same within `tolerance` (states, primitives, transitions, matrices).
bool same_automaton(const Automaton& x, const Automaton& y, double tolerance);

}  // namespace cifs
}  // namespace lacuna
