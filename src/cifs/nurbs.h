// NURBS curves as CIFS automata: mid-knot insertion windows as states, blossoming for the
// transition matrices (../shared/spec/cifs.md, "NURBS curves as CIFS automata").
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "cifs/automaton.h"

namespace lacuna {
namespace cifs {

struct NurbsAutomaton {
  Automaton automaton;                       // symbol 0 = left half, 1 = right half
  std::vector<std::vector<double>> windows;  // the inter-node vector (length 2d - 1) of each state
};

// The automaton of one B-spline piece of degree d >= 1 from its 2d knots t0 .. t(2d-1)
// (non-decreasing, t(d-1) < t(d)). States are the distinct inter-node windows reached by
// repeated mid-knot insertion; each state has d + 1 control points and a segment primitive whose
// end points are the piece's ends. Throws InvalidInput for bad degrees or knots.
NurbsAutomaton nurbs_automaton(int degree, const std::vector<double>& knots);

// The blossom (polar form) of the piece with knots t0 .. t(2d-1) at (x1 .. xd), as the affine
// weights of its d + 1 control points (de Boor's recursion with a different argument per stage).
Eigen::VectorXd blossom_weights(int degree, const std::vector<double>& knots, const std::vector<double>& arguments);

// The knots of the curve's parameter that level `level` puts vertex i at: t(d-1) + i / 2^level *
// (t(d) - t(d-1)), for i = 0 .. 2^level.
double nurbs_vertex_parameter(int degree, const std::vector<double>& knots, int level, uint64_t vertex);

}  // namespace cifs
}  // namespace lacuna
