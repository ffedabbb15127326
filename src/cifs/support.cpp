#include "cifs/support.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "cifs/tessellate.h"
#include "errors.h"

namespace lacuna {
namespace cifs {

Cifs support_tree(const Cifs& surface_in, const SupportOptions& options) {
  if (!(options.fork > 0 && options.fork < 1)) throw InvalidInput("the support's fork must lie strictly between 0 and 1");
  if (!(options.shrink > 0 && options.shrink <= 1)) throw InvalidInput("the support's shrink must lie in (0, 1]");
  if (!(options.base_size_mm >= 0) || !std::isfinite(options.base_size_mm))
    throw InvalidInput("the support's base size must be a finite length >= 0");
  if (surface_in.rational) throw InvalidInput("a support needs a non-rational surface");
  Cifs surface = surface_in;
  complete_primitives(surface.automaton);
  const Automaton& s = surface.automaton;
  for (const State& st : s.states)
    if (st.primitive != Primitive::kQuad || st.vertices.cols() != 4)
      throw InvalidInput("a support stands under a tensor surface (quad pieces); state \"" + st.name + "\" is a " +
                         primitive_name(st.primitive));

  // The root's base: the surface's outline about its centre, flattened and scaled, on the plate.
  const State& first = s.states[size_t(s.initial)];
  const Eigen::Matrix3Xd corners = surface.control_points * first.vertices;
  const Eigen::Vector3d centre = corners.rowwise().mean();
  double reach = 0;
  for (int k = 0; k < 4; ++k) reach = std::max(reach, Eigen::Vector2d(corners(0, k) - centre(0), corners(1, k) - centre(1)).norm());
  if (!(reach > 0)) throw InvalidInput("the surface has no extent seen from above: a support cannot stand under it");
  const double scale = options.base_size_mm > 0 ? 0.5 * options.base_size_mm / reach : 0.25;
  double lowest = HUGE_VAL;
  const int probe = count_pieces(s, 3) <= 4096 ? 3 : 1;
  for_each_piece(surface, probe, [&](const Piece& p) { lowest = std::min(lowest, p.vertices->row(2).minCoeff()); });
  if (!(options.base_center_mm.z < lowest))
    throw InvalidInput("the support's base (z = " + message_number(options.base_center_mm.z) +
                       " mm) must lie below the surface (lowest at z = " + message_number(lowest) + " mm)");

  Automaton tree;
  const int n = int(s.states.size()), trunk = n, trunk_symbol = s.alphabet_size;
  tree.alphabet_size = s.alphabet_size + 1;
  tree.initial = s.initial;
  for (int q = 0; q < n; ++q) {
    const State& sq = s.states[size_t(q)];
    State b;
    b.name = "branch " + sq.name;
    b.primitive = Primitive::kHexahedron;
    b.control_points = sq.control_points + 4;
    b.vertices = Eigen::MatrixXd::Zero(b.control_points, 8);
    for (int c = 0; c < 4; ++c) {
      b.vertices(sq.control_points + c, c) = 1;                       // bottom: the base quad
      b.vertices.block(0, 4 + c, sq.control_points, 1) = sq.vertices.col(c);  // top: the piece's corner c
    }
    tree.states.push_back(b);
  }
  {
    State t;
    t.name = "trunk";
    t.primitive = Primitive::kHexahedron;
    t.control_points = 8;
    tree.states.push_back(t);
  }
  tree.transitions.resize(size_t(n) + 1);
  for (int q = 0; q < n; ++q) {
    const State& sq = s.states[size_t(q)];
    const Eigen::Index k = sq.control_points;
    auto base = [&](int c) { return Eigen::VectorXd::Unit(k + 4, k + c); };
    const Eigen::VectorXd base_centre = (base(0) + base(1) + base(2) + base(3)) / 4;
    Eigen::VectorXd top_centre = Eigen::VectorXd::Zero(k + 4);
    top_centre.head(k) = sq.vertices.rowwise().mean();
    const Eigen::VectorXd fork = (1 - options.fork) * base_centre + options.fork * top_centre;
    auto fork_corner = [&](int c) { return Eigen::VectorXd(fork + options.shrink * (base(c) - base_centre)); };
    for (const Transition& t : s.transitions[size_t(q)]) {
      const Eigen::Index kt = s.states[size_t(t.target)].control_points;
      Eigen::MatrixXd m = Eigen::MatrixXd::Zero(k + 4, kt + 4);
      m.topLeftCorner(k, kt) = t.matrix;
      for (int c = 0; c < 4; ++c) m.col(kt + c) = fork_corner(c);
      tree.transitions[size_t(q)].push_back(Transition{t.symbol, t.target, m});
    }
    Eigen::MatrixXd to_trunk(k + 4, 8);
    for (int c = 0; c < 4; ++c) {
      to_trunk.col(c) = base(c);
      to_trunk.col(4 + c) = fork_corner(c);
    }
    tree.transitions[size_t(q)].push_back(Transition{trunk_symbol, trunk, to_trunk});
  }
  tree.transitions[size_t(trunk)].push_back(Transition{trunk_symbol, trunk, Eigen::MatrixXd::Identity(8, 8)});
  validate(tree);
  complete_primitives(tree);

  Cifs out;
  out.name = surface.name + " support";
  out.automaton = tree;
  const Eigen::Index k0 = first.control_points;
  out.control_points.resize(3, k0 + 4);
  out.control_points.leftCols(k0) = surface.control_points;
  const Eigen::Vector3d plate(options.base_center_mm.x, options.base_center_mm.y, options.base_center_mm.z);
  for (int c = 0; c < 4; ++c)
    out.control_points.col(k0 + c) =
        plate + scale * Eigen::Vector3d(corners(0, c) - centre(0), corners(1, c) - centre(1), 0);
  validate(out);
  return out;
}

}  // namespace cifs
}  // namespace lacuna
