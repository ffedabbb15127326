#include "cifs/junction.h"

#include <cmath>
#include <string>

#include "errors.h"

namespace lacuna {
namespace cifs {
namespace {

void require_curve(const Automaton& a, const char* which) {
  for (const State& s : a.states)
    if (s.primitive != Primitive::kSegment)
      throw InvalidInput(std::string("the junction's ") + which + " must be a curve automaton; state \"" + s.name +
                         "\" is a " + primitive_name(s.primitive));
}

// The side's chord weights: w_l = the projection of the mean row's control point l onto the mean
// row's chord from start to end, so that s^T w = 0 and e^T w = 1 (the chord point of each control
// point). A chord of no length falls back on the least-norm weights with the same two sums.
Eigen::VectorXd chord_weights(const Eigen::MatrixXd& mean_row, const Eigen::VectorXd& s, const Eigen::VectorXd& e,
                              double& chord_length) {
  const Eigen::Vector3d start = mean_row * s, end = mean_row * e, d = end - start;
  chord_length = d.norm();
  const double size = (mean_row.colwise() - start).colwise().norm().maxCoeff();
  if (chord_length > 1e-9 * (1 + size)) {
    Eigen::VectorXd w(mean_row.cols());
    for (Eigen::Index l = 0; l < mean_row.cols(); ++l) w(l) = (mean_row.col(l) - start).dot(d) / d.squaredNorm();
    return w;
  }
  Eigen::MatrixXd c(2, s.size());
  c.row(0) = s.transpose();
  c.row(1) = e.transpose();
  const Eigen::Vector2d rhs(0, 1);
  const Eigen::VectorXd w = c.transpose() * (c * c.transpose()).completeOrthogonalDecomposition().solve(rhs);
  if ((c * w - rhs).norm() > 1e-9) throw InvalidInput("the junction's side starts where it ends and has no chord");
  return w;
}

// The mean over the rows of U of a net's v polygon (3 x kv).
Eigen::MatrixXd mean_row(const Eigen::MatrixXd& net, Eigen::Index ku, Eigen::Index kv) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(3, kv);
  for (Eigen::Index i = 0; i < ku; ++i) m += net.block(0, i * kv, 3, kv);
  return m / double(ku);
}

}  // namespace

bool same_automaton(const Automaton& x, const Automaton& y, double tolerance) {
  if (x.states.size() != y.states.size() || x.initial != y.initial || x.alphabet_size != y.alphabet_size) return false;
  for (size_t q = 0; q < x.states.size(); ++q) {
    if (x.states[q].control_points != y.states[q].control_points || x.states[q].primitive != y.states[q].primitive)
      return false;
    const auto &tx = x.transitions[q], &ty = y.transitions[q];
    if (tx.size() != ty.size()) return false;
    for (size_t t = 0; t < tx.size(); ++t)
      if (tx[t].symbol != ty[t].symbol || tx[t].target != ty[t].target ||
          tx[t].matrix.rows() != ty[t].matrix.rows() || tx[t].matrix.cols() != ty[t].matrix.cols() ||
          (tx[t].matrix - ty[t].matrix).cwiseAbs().maxCoeff() > tolerance)
        return false;
  }
  return true;
}

Cifs junction(const TensorSurface& a_in, const TensorSurface& b_in, const JunctionOptions& options) {
  if (!(options.ratio > 0 && options.ratio < 0.5))
    throw InvalidInput("the junction's ratio must lie strictly between 0 and 0.5 (got " + message_number(options.ratio) + ")");
  if (!(options.amplitude >= 0) || !std::isfinite(options.amplitude))
    throw InvalidInput("the junction's amplitude must be a finite number >= 0");
  TensorSurface a = a_in, b = b_in;
  for (Automaton* f : {&a.u, &a.v, &b.u, &b.v}) {
    validate(*f);
    complete_primitives(*f);
  }
  require_curve(a.u, "u direction");
  require_curve(a.v, "side A's v direction");
  require_curve(b.v, "side B's v direction");
  if (!same_automaton(a.u, b.u, 1e-12))
    throw InvalidInput("A and B must share their u automaton (the junction runs along their common border's "
                       "nature): give both surfaces the same first factor");
  const Eigen::Index ku = a.u.states[size_t(a.u.initial)].control_points;
  const Eigen::Index ka = a.v.states[size_t(a.v.initial)].control_points;
  const Eigen::Index kb = b.v.states[size_t(b.v.initial)].control_points;
  const Eigen::Index kj = ka + kb;
  if (a.control_points.rows() != 3 || a.control_points.cols() != ku * ka || b.control_points.rows() != 3 ||
      b.control_points.cols() != ku * kb)
    throw InvalidInput("the junction's sides need " + std::to_string(ku * ka) + " and " + std::to_string(ku * kb) +
                       " control points (u x v, non-rational)");

  const Eigen::VectorXd sa = a.v.states[size_t(a.v.initial)].vertices.col(0), ea = a.v.states[size_t(a.v.initial)].vertices.col(1);
  const Eigen::VectorXd sb = b.v.states[size_t(b.v.initial)].vertices.col(0), eb = b.v.states[size_t(b.v.initial)].vertices.col(1);
  auto on_a = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd out = Eigen::VectorXd::Zero(kj);
    out.head(ka) = x;
    return out;
  };
  auto on_b = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd out = Eigen::VectorXd::Zero(kj);
    out.tail(kb) = x;
    return out;
  };
  const Eigen::VectorXd SA = on_a(sa), EA = on_a(ea), SB = on_b(sb), EB = on_b(eb);
  const double r = options.ratio;
  const Eigen::VectorXd P = EA, R = SB, P1 = (1 - r) * P + r * R, R1 = (1 - r) * R + r * P;

  const Eigen::MatrixXd row_a = mean_row(a.control_points, ku, ka), row_b = mean_row(b.control_points, ku, kb);
  const double gap = (row_b * sb - row_a * ea).norm();
  const double size = std::max((row_a.colwise() - row_a * ea).colwise().norm().maxCoeff(),
                               (row_b.colwise() - row_b * sb).colwise().norm().maxCoeff());
  if (!(gap > 1e-9 * (1 + size)))
    throw InvalidInput("A's end (v = 1) and B's start (v = 0) coincide: there is no gap for a junction to fill");
  double chord_a = 0, chord_b = 0;
  const Eigen::VectorXd w = chord_weights(row_a, sa, ea, chord_a), z = chord_weights(row_b, sb, eb, chord_b);
  // A similar copy of a side over a chord r x the gap has its deviation scaled by r x gap / chord.
  const double dev_a = options.amplitude * r * (chord_a > 0 ? gap / chord_a : 1);
  const double dev_b = options.amplitude * r * (chord_b > 0 ? gap / chord_b : 1);

  Eigen::MatrixXd t0(kj, ka), t2(kj, kb);
  for (Eigen::Index l = 0; l < ka; ++l)
    t0.col(l) = (1 - w(l)) * P + w(l) * P1 + dev_a * (on_a(Eigen::VectorXd::Unit(ka, l)) - (1 - w(l)) * SA - w(l) * EA);
  for (Eigen::Index l = 0; l < kb; ++l)
    t2.col(l) = (1 - z(l)) * R1 + z(l) * R + dev_b * (on_b(Eigen::VectorXd::Unit(kb, l)) - (1 - z(l)) * SB - z(l) * EB);
  const double k = 1 - 2 * r;
  const Eigen::MatrixXd t1 = k * Eigen::MatrixXd::Identity(kj, kj) + r * (EA + SB) * Eigen::RowVectorXd::Ones(kj);

  // W: [root,] j, Va's states, Vb's states.
  Automaton wa;
  const int root = options.sides ? 0 : -1, j = options.sides ? 1 : 0;
  const int oa = j + 1, ob = oa + int(a.v.states.size());
  auto add_state = [&](State s) {
    wa.states.push_back(std::move(s));
    wa.transitions.emplace_back();
  };
  if (options.sides) {
    State s;
    s.name = "junction+sides";
    s.control_points = int(kj);
    s.vertices.resize(kj, 2);
    s.vertices.col(0) = SA;
    s.vertices.col(1) = EB;
    add_state(s);
  }
  {
    State s;
    s.name = "junction";
    s.control_points = int(kj);
    s.vertices.resize(kj, 2);
    s.vertices.col(0) = P;
    s.vertices.col(1) = R;
    add_state(s);
  }
  for (const Automaton* side : {&a.v, &b.v}) {
    const int offset = side == &a.v ? oa : ob;
    for (size_t q = 0; q < side->states.size(); ++q) {
      State s = side->states[q];
      s.name = std::string(side == &a.v ? "A:" : "B:") + s.name;
      add_state(s);
      for (const Transition& t : side->transitions[q])
        wa.transitions.back().push_back(Transition{t.symbol, t.target + offset, t.matrix});
    }
  }
  const int a0 = oa + a.v.initial, b0 = ob + b.v.initial;
  wa.transitions[size_t(j)] = {Transition{0, a0, t0}, Transition{1, j, t1}, Transition{2, b0, t2}};
  int alphabet = std::max({3, a.v.alphabet_size, b.v.alphabet_size});
  if (options.sides) {
    // One step of each part: A's first transitions on A's polygon, J's, B's on B's polygon.
    Eigen::MatrixXd select_a = Eigen::MatrixXd::Zero(kj, ka), select_b = Eigen::MatrixXd::Zero(kj, kb);
    select_a.topRows(ka).setIdentity();
    select_b.bottomRows(kb).setIdentity();
    const int na = a.v.alphabet_size;
    auto& out = wa.transitions[size_t(root)];
    for (const Transition& t : a.v.transitions[size_t(a.v.initial)])
      out.push_back(Transition{t.symbol, t.target + oa, select_a * t.matrix});
    for (const Transition& t : wa.transitions[size_t(j)]) out.push_back(Transition{na + t.symbol, t.target, t.matrix});
    for (const Transition& t : b.v.transitions[size_t(b.v.initial)])
      out.push_back(Transition{na + 3 + t.symbol, t.target + ob, select_b * t.matrix});
    alphabet = std::max(alphabet, na + 3 + b.v.alphabet_size);
  }
  wa.alphabet_size = alphabet;
  wa.initial = 0;
  validate(wa);

  Cifs out;
  out.name = options.sides ? "junction with sides" : "junction";
  out.automaton = tensor_product(a.u, wa);
  out.control_points.resize(3, ku * kj);
  for (Eigen::Index i = 0; i < ku; ++i) {
    out.control_points.block(0, i * kj, 3, ka) = a.control_points.block(0, i * ka, 3, ka);
    out.control_points.block(0, i * kj + ka, 3, kb) = b.control_points.block(0, i * kb, 3, kb);
  }
  validate(out);
  return out;
}

}  // namespace cifs
}  // namespace lacuna
