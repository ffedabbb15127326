#include "cifs/junction.h"

#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

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

// The parameter of a straight segment drawn at constant speed, in every state of a curve automaton: g_s
// with g_s . start = 0, g_s . end = 1 and, for the i-th of a state's m transitions (to t, matrix M),
// M^T g_s = i / m + g_t / m. A polygon X + g_s (Y - X) then draws the segment from X to Y and its i-th
// piece is the i-th m-th of it (linear precision, the same split in every state). Empty when the
// automaton has no such parameter.
std::vector<Eigen::VectorXd> linear_parameter(const Automaton& a) {
  std::vector<Eigen::Index> offset(a.states.size() + 1, 0);
  Eigen::Index equations = 0;
  for (size_t q = 0; q < a.states.size(); ++q) {
    offset[q + 1] = offset[q] + a.states[q].control_points;
    equations += 2;
    for (const Transition& t : a.transitions[q]) equations += a.states[size_t(t.target)].control_points;
  }
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(equations, offset.back());
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(equations);
  Eigen::Index row = 0;
  for (size_t q = 0; q < a.states.size(); ++q) {
    const State& s = a.states[q];
    m.block(row, offset[q], 1, s.control_points) = s.vertices.col(0).transpose();
    m.block(row + 1, offset[q], 1, s.control_points) = s.vertices.col(1).transpose();
    rhs(row + 1) = 1;
    row += 2;
    const double pieces = double(a.transitions[q].size());
    for (size_t i = 0; i < a.transitions[q].size(); ++i) {
      const Transition& t = a.transitions[q][i];
      const Eigen::Index kt = a.states[size_t(t.target)].control_points;
      m.block(row, offset[q], kt, s.control_points) = t.matrix.transpose();
      m.block(row, offset[size_t(t.target)], kt, kt) -= Eigen::MatrixXd::Identity(kt, kt) / pieces;
      rhs.segment(row, kt).setConstant(double(i) / pieces);
      row += kt;
    }
  }
  const Eigen::VectorXd g = m.completeOrthogonalDecomposition().solve(rhs);
  if (!((m * g - rhs).cwiseAbs().maxCoeff() <= 1e-9 * (1 + g.cwiseAbs().maxCoeff()))) return {};
  std::vector<Eigen::VectorXd> out;
  for (size_t q = 0; q < a.states.size(); ++q) out.push_back(g.segment(offset[q], a.states[q].control_points));
  return out;
}

// The product of two u automata of different natures with a curve automaton W across: control point l
// of W's state w follows nature type[w][l] (0: ua's, 1: ub's), so a state is (w, the ua state, the ub
// state), -1 for a nature w does not use, with |u state| x |w| control points (index iu * |w| + l; a
// state using both natures needs u states of equal sizes: the initial pair's are the caller's to check,
// every pair reached is checked here, as are paired states that split into other symbols). On u symbol a and W's transition T to w',
// every target row follows its own nature: the matrix is the sum over the natures n of
// kron(M^n_a, T restricted to w''s rows of nature n), and T may only join rows of one nature. The
// corners of a quad are those of each row's nature, so when every row has nature 0 this is
// tensor_product(ua, w). Symbols a * |W| + b as there.
Automaton typed_product(const Automaton& ua, const Automaton& ub, const Automaton& w,
                        const std::vector<std::vector<int>>& type) {
  const Automaton* u[2] = {&ua, &ub};
  std::vector<int> uses(w.states.size(), 0);
  for (size_t q = 0; q < w.states.size(); ++q)
    for (int t : type[q]) uses[q] |= 1 << t;
  auto mask = [&](int q, int n) {
    Eigen::VectorXd m(w.states[size_t(q)].control_points);
    for (Eigen::Index l = 0; l < m.size(); ++l) m(l) = type[size_t(q)][size_t(l)] == n ? 1 : 0;
    return m;
  };
  Automaton out;
  out.alphabet_size = ua.alphabet_size * w.alphabet_size;
  using Key = std::array<int, 3>;
  std::map<Key, int> index;
  std::vector<Key> queue{{w.initial, uses[size_t(w.initial)] & 1 ? ua.initial : -1, uses[size_t(w.initial)] & 2 ? ub.initial : -1}};
  index[queue[0]] = 0;
  const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (size_t i = 0; i < queue.size(); ++i) {
    const Key key = queue[i];
    const State& sw = w.states[size_t(key[0])];
    // Both natures' u states have one size: the caller checks the initial pair, the transitions below the rest.
    int n_u = -1;
    std::string u_name;
    for (int n = 0; n < 2; ++n) {
      if (key[1 + n] < 0) continue;
      const State& su = u[n]->states[size_t(key[1 + n])];
      n_u = su.control_points;
      u_name += (u_name.empty() ? "" : "|") + (su.name.empty() ? std::to_string(key[1 + n]) : su.name);
    }
    State s;
    s.name = u_name + "x" + (sw.name.empty() ? std::to_string(key[0]) : sw.name);
    s.control_points = n_u * sw.control_points;
    s.primitive = Primitive::kQuad;
    s.vertices = Eigen::MatrixXd::Zero(s.control_points, 4);
    for (int c = 0; c < 4; ++c)
      for (int n = 0; n < 2; ++n)
        if (key[1 + n] >= 0)
          s.vertices.col(c) += kronecker(u[n]->states[size_t(key[1 + n])].vertices.col(corner[c][0]),
                                         sw.vertices.col(corner[c][1]).cwiseProduct(mask(key[0], n)));
    out.states.push_back(s);
    out.transitions.emplace_back();
    const int lead = key[1] >= 0 ? 0 : 1;
    if (key[1] >= 0 && key[2] >= 0 &&
        u[0]->transitions[size_t(key[1])].size() != u[1]->transitions[size_t(key[2])].size())
      throw InvalidInput("the junction's u automata split their pieces differently where they meet (states \"" +
                         u[0]->states[size_t(key[1])].name + "\" and \"" + u[1]->states[size_t(key[2])].name + "\")");
    for (const Transition& tu : u[lead]->transitions[size_t(key[1 + lead])]) {
      const Transition* tn[2] = {nullptr, nullptr};
      for (int n = 0; n < 2; ++n)
        if (key[1 + n] >= 0) tn[n] = find_transition(*u[n], key[1 + n], tu.symbol);
      if ((key[1] >= 0 && !tn[0]) || (key[2] >= 0 && !tn[1]))
        throw InvalidInput("the junction's u automata split their pieces differently where they meet (symbol " +
                           std::to_string(tu.symbol) + " is defined in one only)");
      if (tn[0] && tn[1] &&
          u[0]->states[size_t(tn[0]->target)].control_points != u[1]->states[size_t(tn[1]->target)].control_points)
        throw InvalidInput("the junction's u automata differ in size where they meet (" +
                           std::to_string(u[0]->states[size_t(tn[0]->target)].control_points) + " and " +
                           std::to_string(u[1]->states[size_t(tn[1]->target)].control_points) +
                           " control points after symbol " + std::to_string(tu.symbol) + ")");
      for (const Transition& tw : w.transitions[size_t(key[0])]) {
        Key target{tw.target, -1, -1};
        Eigen::MatrixXd matrix;
        for (int n = 0; n < 2; ++n) {
          if (!(uses[size_t(tw.target)] & (1 << n))) continue;
          if (!tn[n]) throw std::logic_error("junction: a transition joins rows of two natures");
          target[size_t(1 + n)] = tn[n]->target;
          const Eigen::MatrixXd part = kronecker(tn[n]->matrix, tw.matrix * mask(tw.target, n).asDiagonal());
          matrix = matrix.size() ? Eigen::MatrixXd(matrix + part) : part;
        }
        auto [it, fresh] = index.emplace(target, int(queue.size()));
        if (fresh) queue.push_back(target);
        out.transitions[i].push_back(Transition{tu.symbol * w.alphabet_size + tw.symbol, it->second, matrix});
      }
    }
  }
  out.initial = 0;
  return out;
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
  require_curve(a.u, "side A's u direction");
  require_curve(b.u, "side B's u direction");
  require_curve(a.v, "side A's v direction");
  require_curve(b.v, "side B's v direction");
  const bool shared = same_automaton(a.u, b.u, 1e-12);
  const Eigen::Index ku = a.u.states[size_t(a.u.initial)].control_points;
  if (!shared && (b.u.states[size_t(b.u.initial)].control_points != ku || b.u.alphabet_size != a.u.alphabet_size))
    throw InvalidInput("A's and B's u automata differ in their control points (" + std::to_string(ku) + " and " +
                       std::to_string(b.u.states[size_t(b.u.initial)].control_points) + ") or symbols (" +
                       std::to_string(a.u.alphabet_size) + " and " + std::to_string(b.u.alphabet_size) +
                       "): the borders must share one control polygon");
  const Eigen::Index ka = a.v.states[size_t(a.v.initial)].control_points;
  const Eigen::Index kb = b.v.states[size_t(b.v.initial)].control_points;
  // J's v polygon per row of u: A's ka points, then (natures apart) the two free points F_A and F_B,
  // then B's kb points.
  const Eigen::Index free = shared ? 0 : 2, ob = ka + free, kj = ka + free + kb;
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
    out.segment(ob, kb) = x;
    return out;
  };
  const Eigen::VectorXd SA = on_a(sa), EA = on_a(ea), SB = on_b(sb), EB = on_b(eb);
  const double r = options.ratio, k = 1 - 2 * r;
  const Eigen::VectorXd P = EA, R = SB;

  const Eigen::MatrixXd row_a = mean_row(a.control_points, ku, ka), row_b = mean_row(b.control_points, ku, kb);
  const double size = std::max((row_a.colwise() - row_a * ea).colwise().norm().maxCoeff(),
                               (row_b.colwise() - row_b * sb).colwise().norm().maxCoeff());
  Eigen::VectorXd P1, R1;
  Eigen::MatrixXd t1, free_points;  // free_points: 3 x 2 ku, F_A and F_B per row of u
  double piece_a = 0, piece_b = 0;   // the chords of T0's and T2's pieces
  if (shared) {
    const double gap = (row_b * sb - row_a * ea).norm();
    if (!(gap > 1e-9 * (1 + size)))
      throw InvalidInput("A's end (v = 1) and B's start (v = 0) coincide: there is no gap for a junction to fill");
    P1 = (1 - r) * P + r * R;
    R1 = (1 - r) * R + r * P;
    t1 = k * Eigen::MatrixXd::Identity(kj, kj) + r * (EA + SB) * Eigen::RowVectorXd::Ones(kj);
    piece_a = piece_b = r * gap;
  } else {
    // Borders of two natures along u meet on a straight seam S from X to Y that both u automata draw
    // with the same pieces: F_A draws it in A's nature, F_B in B's. T1 keeps the natures apart (a
    // homothety of ratio 1 - 2r towards F_A on A's rows, towards F_B on B's), so J's pieces of A's
    // nature shrink towards S from A's border and those of B's nature from B's.
    const std::vector<Eigen::VectorXd> ga = linear_parameter(a.u), gb = linear_parameter(b.u);
    if (ga.empty() || gb.empty())
      throw InvalidInput(std::string("the junction of two u automata needs each to draw a straight segment with equal "
                                     "pieces (linear precision), where the two natures meet; side ") +
                         (ga.empty() ? "A" : "B") + "'s does not");
    Eigen::MatrixXd border_a(3, ku), border_b(3, ku);
    for (Eigen::Index i = 0; i < ku; ++i) {
      border_a.col(i) = a.control_points.block(0, i * ka, 3, ka) * ea;
      border_b.col(i) = b.control_points.block(0, i * kb, 3, kb) * sb;
    }
    const State &ua = a.u.states[size_t(a.u.initial)], &ub = b.u.states[size_t(b.u.initial)];
    const Eigen::Vector3d x = 0.5 * (border_a * ua.vertices.col(0) + border_b * ub.vertices.col(0));
    const Eigen::Vector3d y = 0.5 * (border_a * ua.vertices.col(1) + border_b * ub.vertices.col(1));
    if (!((y - x).norm() > 1e-9 * (1 + size)))
      throw InvalidInput("A's and B's borders start and end at the same point: the seam between their natures would "
                         "be a point");
    free_points.resize(3, 2 * ku);
    double far_a = 0, far_b = 0;
    for (Eigen::Index i = 0; i < ku; ++i) {
      free_points.col(2 * i) = x + ga[size_t(a.u.initial)](i) * (y - x);
      free_points.col(2 * i + 1) = x + gb[size_t(b.u.initial)](i) * (y - x);
      far_a = std::max(far_a, (border_a.col(i) - free_points.col(2 * i)).norm());
      far_b = std::max(far_b, (border_b.col(i) - free_points.col(2 * i + 1)).norm());
    }
    if (!(far_a > 1e-9 * (1 + size)) || !(far_b > 1e-9 * (1 + size)))
      throw InvalidInput(std::string("side ") + (far_a > 1e-9 * (1 + size) ? "B" : "A") +
                         "'s border is already the straight seam where the natures meet: there is nothing to join");
    const Eigen::VectorXd FA = Eigen::VectorXd::Unit(kj, ka), FB = Eigen::VectorXd::Unit(kj, ka + 1);
    P1 = k * P + (1 - k) * FA;
    R1 = k * R + (1 - k) * FB;
    t1 = k * Eigen::MatrixXd::Identity(kj, kj);
    for (Eigen::Index l = 0; l < kj; ++l) t1.col(l) += (1 - k) * (l <= ka ? FA : FB);
    Eigen::Vector3d mean_fa = Eigen::Vector3d::Zero(), mean_fb = Eigen::Vector3d::Zero();
    for (Eigen::Index i = 0; i < ku; ++i) {
      mean_fa += free_points.col(2 * i) / double(ku);
      mean_fb += free_points.col(2 * i + 1) / double(ku);
    }
    piece_a = (1 - k) * (mean_fa - row_a * ea).norm();
    piece_b = (1 - k) * (mean_fb - row_b * sb).norm();
  }
  double chord_a = 0, chord_b = 0;
  const Eigen::VectorXd w = chord_weights(row_a, sa, ea, chord_a), z = chord_weights(row_b, sb, eb, chord_b);
  // A similar copy of a side over a piece's chord has its deviation scaled by that chord / the side's.
  const double dev_a = options.amplitude * (chord_a > 0 ? piece_a / chord_a : r);
  const double dev_b = options.amplitude * (chord_b > 0 ? piece_b / chord_b : r);

  Eigen::MatrixXd t0(kj, ka), t2(kj, kb);
  for (Eigen::Index l = 0; l < ka; ++l)
    t0.col(l) = (1 - w(l)) * P + w(l) * P1 + dev_a * (on_a(Eigen::VectorXd::Unit(ka, l)) - (1 - w(l)) * SA - w(l) * EA);
  for (Eigen::Index l = 0; l < kb; ++l)
    t2.col(l) = (1 - z(l)) * R1 + z(l) * R + dev_b * (on_b(Eigen::VectorXd::Unit(kb, l)) - (1 - z(l)) * SB - z(l) * EB);

  // W: [root,] j, Va's states, Vb's states; the nature of each state's control points alongside.
  Automaton wa;
  std::vector<std::vector<int>> nature;
  std::vector<int> j_nature(size_t(kj), 0);
  if (!shared)
    for (Eigen::Index l = ka + 1; l < kj; ++l) j_nature[size_t(l)] = 1;
  const int root = options.sides ? 0 : -1, j = options.sides ? 1 : 0;
  const int oa = j + 1, obs = oa + int(a.v.states.size());
  auto add_state = [&](State s, int n) {
    nature.push_back(n < 0 ? j_nature : std::vector<int>(size_t(s.control_points), n));
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
    add_state(s, -1);
  }
  {
    State s;
    s.name = "junction";
    s.control_points = int(kj);
    s.vertices.resize(kj, 2);
    s.vertices.col(0) = P;
    s.vertices.col(1) = R;
    add_state(s, -1);
  }
  for (const Automaton* side : {&a.v, &b.v}) {
    const int offset = side == &a.v ? oa : obs;
    for (size_t q = 0; q < side->states.size(); ++q) {
      State s = side->states[q];
      s.name = std::string(side == &a.v ? "A:" : "B:") + s.name;
      add_state(s, side == &a.v || shared ? 0 : 1);
      for (const Transition& t : side->transitions[q])
        wa.transitions.back().push_back(Transition{t.symbol, t.target + offset, t.matrix});
    }
  }
  const int a0 = oa + a.v.initial, b0 = obs + b.v.initial;
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
      out.push_back(Transition{na + 3 + t.symbol, t.target + obs, select_b * t.matrix});
    alphabet = std::max(alphabet, na + 3 + b.v.alphabet_size);
  }
  wa.alphabet_size = alphabet;
  wa.initial = 0;
  validate(wa);
  complete_primitives(wa);

  Cifs out;
  out.name = options.sides ? "junction with sides" : "junction";
  out.automaton = typed_product(a.u, shared ? a.u : b.u, wa, nature);
  out.control_points.resize(3, ku * kj);
  for (Eigen::Index i = 0; i < ku; ++i) {
    out.control_points.block(0, i * kj, 3, ka) = a.control_points.block(0, i * ka, 3, ka);
    if (!shared) out.control_points.block(0, i * kj + ka, 3, 2) = free_points.block(0, 2 * i, 3, 2);
    out.control_points.block(0, i * kj + ob, 3, kb) = b.control_points.block(0, i * kb, 3, kb);
  }
  validate(out);
  return out;
}

}  // namespace cifs
}  // namespace lacuna
