// Controlled iterated function systems (CIFS): an automaton whose transitions carry barycentric
// matrices, and control points that place its attractor in space (../shared/spec/cifs.md).
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace lacuna {
namespace cifs {

// What one piece of a state looks like once placed: its vertices are barycentric columns over the
// state's control points.
enum class Primitive { kPoint, kSegment, kTriangle, kQuad, kTetrahedron, kHexahedron, kPolygon, kPolyhedron };

// Parses "segment", "triangle", ... ; throws InvalidInput for any other word.
Primitive primitive_from_name(const std::string& name);
const char* primitive_name(Primitive primitive);
// 0 for points, 1 for curves, 2 for surfaces, 3 for volumes.
int primitive_dimension(Primitive primitive);

struct State {
  std::string name;
  int control_points = 2;            // k: the dimension of the state's barycentric space
  Primitive primitive = Primitive::kSegment;
  Eigen::MatrixXd vertices;          // k x m barycentric vertices of the primitive (columns sum to 1);
                                     // empty: computed from the automaton (end points, corners)
  std::vector<std::vector<int>> faces;  // polygon: its loop; polyhedron: outward faces (counter-clockwise)
};

struct Transition {
  int symbol = 0;          // letter of the alphabet
  int target = 0;          // the state reached
  Eigen::MatrixXd matrix;  // k(source) x k(target); column j: new control point j from the source's
};

struct Automaton {
  std::vector<State> states;
  std::vector<std::vector<Transition>> transitions;  // per state, ordered by symbol
  int initial = 0;
  int alphabet_size = 2;
};

// A CIFS placed in space: the automaton and the control points of its initial state.
struct Cifs {
  std::string name;
  Automaton automaton;
  Eigen::MatrixXd control_points;  // 3 x k, or 4 x k homogeneous (w x, w y, w z, w) when rational
  bool rational = false;
};

// Checks sizes, references and that every matrix column and primitive vertex sums to 1 (within
// 1e-9); throws InvalidInput naming the state and transition.
void validate(const Automaton& automaton);
void validate(const Cifs& cifs);

// The transition of `state` on `symbol`, or nullptr when undefined.
const Transition* find_transition(const Automaton& automaton, int state, int symbol);

// States with a transition to themselves (stationary states).
std::vector<int> stationary_states(const Automaton& automaton);

// Fixed point of a square barycentric matrix: its eigenvector for eigenvalue 1, normalised to
// sum 1. Throws InvalidInput when 1 is not an eigenvalue or the eigenvector sums to 0.
Eigen::VectorXd fixed_point(const Eigen::MatrixXd& matrix);

// The barycentric point (in `state`'s space) addressed by the infinite word symbol^ω: follows the
// symbol until a state repeats, takes the fixed point of the loop's product and maps it back.
// Throws InvalidInput if the symbol is undefined on the way.
Eigen::VectorXd limit_point(const Automaton& automaton, int state, int symbol);

// The attractor near a fixed point: the loop's matrix M maps differences of barycentric points (their
// coordinates sum to 0) to differences, and the attractor approaches the fixed point along the
// eigenvectors of M's largest eigenvalues on that space. A curve has a tangent there when the
// largest is real and simple (strictly larger in modulus than the next), a surface a tangent plane
// when the two largest are real and larger than the third.
struct FixedPointFrame {
  Eigen::VectorXd point;                    // barycentric
  std::vector<Eigen::VectorXd> directions;  // `dimension` difference vectors into the attractor (smooth only)
  std::vector<double> rates;                // their eigenvalues
  bool smooth = false;
  std::string reason;                       // why not smooth
};

// The frame of the fixed point of `matrix` for an attractor of `dimension` 1 or 2; each direction
// is oriented so that `toward` (another barycentric point of the attractor) lies on its positive
// side. Throws as fixed_point().
FixedPointFrame fixed_point_frame(const Eigen::MatrixXd& matrix, int dimension, const Eigen::VectorXd& toward);

// The frame at limit_point(automaton, state, symbol): the loop's frame mapped back along the way.
// `toward` is a barycentric point of `state`'s attractor other than the limit point.
FixedPointFrame limit_frame(const Automaton& automaton, int state, int symbol, int dimension,
                            const Eigen::VectorXd& toward);

// The vertices of every state's primitive: those given, or for segments the end points (first and
// last symbol repeated), for quads of a tensor product the four corners. Fills State::vertices.
void complete_primitives(Automaton& automaton);

// The Kronecker product (row i_a * rows(b) + i_b, column j_a * cols(b) + j_b): the matrices of a tensor product.
Eigen::MatrixXd kronecker(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// Tensor product: states are the pairs reachable from the two initial states, symbols pairs
// (a * |B| + b), matrices Kronecker products (control point index i_a * k_b + i_b).
Automaton tensor_product(const Automaton& a, const Automaton& b);

// The words of `automaton` restricted to those a pattern automaton accepts (its transitions'
// matrices are ignored; the alphabets must agree).
Automaton restrict_words(const Automaton& automaton, const Automaton& pattern);

}  // namespace cifs
}  // namespace lacuna
