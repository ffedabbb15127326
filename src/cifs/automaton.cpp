#include "cifs/automaton.h"

#include <cmath>
#include <complex>
#include <map>
#include <string>

#include "errors.h"

namespace lacuna {
namespace cifs {
namespace {

constexpr double kSumTolerance = 1e-9;

std::string state_label(const Automaton& a, int q) {
  const std::string& name = a.states[size_t(q)].name;
  return "state " + (name.empty() ? std::to_string(q) : "\"" + name + "\"");
}

// Number of vertices a primitive has when the control points are its vertices.
int natural_vertex_count(Primitive p) {
  switch (p) {
    case Primitive::kPoint: return 1;
    case Primitive::kSegment: return 2;
    case Primitive::kTriangle: return 3;
    case Primitive::kQuad: return 4;
    case Primitive::kTetrahedron: return 4;
    case Primitive::kHexahedron: return 8;
    default: return -1;
  }
}

}  // namespace

Eigen::MatrixXd kronecker(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  Eigen::MatrixXd out(a.rows() * b.rows(), a.cols() * b.cols());
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (Eigen::Index j = 0; j < a.cols(); ++j) out.block(i * b.rows(), j * b.cols(), b.rows(), b.cols()) = a(i, j) * b;
  return out;
}

Primitive primitive_from_name(const std::string& name) {
  static const std::map<std::string, Primitive> kNames = {
      {"point", Primitive::kPoint},           {"segment", Primitive::kSegment},
      {"triangle", Primitive::kTriangle},     {"quad", Primitive::kQuad},
      {"tetrahedron", Primitive::kTetrahedron}, {"hexahedron", Primitive::kHexahedron},
      {"polygon", Primitive::kPolygon},       {"polyhedron", Primitive::kPolyhedron}};
  auto it = kNames.find(name);
  if (it == kNames.end())
    throw InvalidInput("unknown primitive \"" + name +
                       "\" (expected point, segment, triangle, quad, tetrahedron, hexahedron, polygon or polyhedron)");
  return it->second;
}

const char* primitive_name(Primitive p) {
  switch (p) {
    case Primitive::kPoint: return "point";
    case Primitive::kSegment: return "segment";
    case Primitive::kTriangle: return "triangle";
    case Primitive::kQuad: return "quad";
    case Primitive::kTetrahedron: return "tetrahedron";
    case Primitive::kHexahedron: return "hexahedron";
    case Primitive::kPolygon: return "polygon";
    case Primitive::kPolyhedron: return "polyhedron";
  }
  return "?";
}

int primitive_dimension(Primitive p) {
  switch (p) {
    case Primitive::kPoint: return 0;
    case Primitive::kSegment: return 1;
    case Primitive::kTriangle:
    case Primitive::kQuad:
    case Primitive::kPolygon: return 2;
    default: return 3;
  }
}

void validate(const Automaton& a) {
  if (a.states.empty()) throw InvalidInput("the automaton has no states");
  if (a.alphabet_size < 1) throw InvalidInput("the alphabet is empty");
  if (a.initial < 0 || size_t(a.initial) >= a.states.size())
    throw InvalidInput("the initial state " + std::to_string(a.initial) + " does not exist");
  if (a.transitions.size() != a.states.size())
    throw InvalidInput("expected a list of transitions for each of the " + std::to_string(a.states.size()) + " states");
  for (size_t q = 0; q < a.states.size(); ++q) {
    const State& s = a.states[q];
    const std::string where = state_label(a, int(q));
    if (s.control_points < 1) throw InvalidInput(where + ": needs at least one control point");
    if (s.vertices.size() > 0) {
      if (s.vertices.rows() != s.control_points)
        throw InvalidInput(where + ": primitive vertices have " + std::to_string(s.vertices.rows()) +
                           " barycentric coordinates, expected " + std::to_string(s.control_points));
      for (Eigen::Index v = 0; v < s.vertices.cols(); ++v)
        if (std::fabs(s.vertices.col(v).sum() - 1.0) > kSumTolerance || !s.vertices.col(v).allFinite())
          throw InvalidInput(where + ": primitive vertex " + std::to_string(v) + " does not sum to 1");
      for (const auto& face : s.faces)
        for (int i : face)
          if (i < 0 || i >= s.vertices.cols())
            throw InvalidInput(where + ": a face names vertex " + std::to_string(i) + ", which does not exist");
    }
    int last_symbol = -1;
    for (size_t t = 0; t < a.transitions[q].size(); ++t) {
      const Transition& tr = a.transitions[q][t];
      const std::string here = where + ", transition " + std::to_string(t);
      if (tr.symbol < 0 || tr.symbol >= a.alphabet_size)
        throw InvalidInput(here + ": symbol " + std::to_string(tr.symbol) + " is outside the alphabet of " +
                           std::to_string(a.alphabet_size));
      if (tr.symbol <= last_symbol)
        throw InvalidInput(here + ": transitions must be listed by increasing symbol, each at most once");
      last_symbol = tr.symbol;
      if (tr.target < 0 || size_t(tr.target) >= a.states.size())
        throw InvalidInput(here + ": target state " + std::to_string(tr.target) + " does not exist");
      const int rows = s.control_points, cols = a.states[size_t(tr.target)].control_points;
      if (tr.matrix.rows() != rows || tr.matrix.cols() != cols)
        throw InvalidInput(here + ": matrix is " + std::to_string(tr.matrix.rows()) + " x " +
                           std::to_string(tr.matrix.cols()) + ", expected " + std::to_string(rows) + " x " +
                           std::to_string(cols) + " (source control points x target control points)");
      if (!tr.matrix.allFinite()) throw InvalidInput(here + ": matrix has non-finite entries");
      for (Eigen::Index c = 0; c < tr.matrix.cols(); ++c)
        if (std::fabs(tr.matrix.col(c).sum() - 1.0) > kSumTolerance)
          throw InvalidInput(here + ": column " + std::to_string(c) + " sums to " +
                             message_number(tr.matrix.col(c).sum()) + ", expected 1 (barycentric)");
    }
  }
}

void validate(const Cifs& c) {
  validate(c.automaton);
  const int k = c.automaton.states[size_t(c.automaton.initial)].control_points;
  const int rows = c.rational ? 4 : 3;
  if (c.control_points.rows() != rows || c.control_points.cols() != k)
    throw InvalidInput("expected " + std::to_string(k) + " control points of " + std::to_string(rows) +
                       " coordinates, got " + std::to_string(c.control_points.cols()) + " of " +
                       std::to_string(c.control_points.rows()));
  if (!c.control_points.allFinite()) throw InvalidInput("control points must be finite");
  if (c.rational && (c.control_points.row(3).array() <= 0).any())
    throw InvalidInput("rational weights must be positive");
}

const Transition* find_transition(const Automaton& a, int state, int symbol) {
  for (const Transition& t : a.transitions[size_t(state)])
    if (t.symbol == symbol) return &t;
  return nullptr;
}

std::vector<int> stationary_states(const Automaton& a) {
  std::vector<int> out;
  for (size_t q = 0; q < a.states.size(); ++q)
    for (const Transition& t : a.transitions[q])
      if (t.target == int(q)) {
        out.push_back(int(q));
        break;
      }
  return out;
}

Eigen::VectorXd fixed_point(const Eigen::MatrixXd& m) {
  if (m.rows() != m.cols()) throw InvalidInput("a fixed point needs a square matrix");
  const Eigen::Index k = m.rows();
  // Solve (M - I) x = 0 with sum(x) = 1: the stacked least-squares system is exact when 1 is an
  // eigenvalue, and its residual tells when it is not.
  Eigen::MatrixXd a(k + 1, k);
  a.topRows(k) = m - Eigen::MatrixXd::Identity(k, k);
  a.row(k).setOnes();
  Eigen::VectorXd b = Eigen::VectorXd::Zero(k + 1);
  b(k) = 1;
  Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  if (!x.allFinite() || (a * x - b).norm() > 1e-9 * (1 + m.norm()))
    throw InvalidInput("the matrix has no fixed point normalised to sum 1 (1 is not an eigenvalue)");
  return x;
}

namespace {

// symbol^omega from `state`: the matrices of the way to the loop (their product), the loop's
// product, and the state the loop starts at. Throws InvalidInput if the symbol is undefined on the way.
struct SymbolLoop {
  Eigen::MatrixXd prefix, loop;
  int loop_state = 0;
};

SymbolLoop follow_symbol(const Automaton& a, int state, int symbol) {
  std::vector<int> path{state};
  std::vector<const Transition*> steps;
  std::map<int, size_t> seen{{state, 0}};
  for (;;) {
    const Transition* t = find_transition(a, path.back(), symbol);
    if (!t)
      throw InvalidInput(state_label(a, path.back()) + " has no transition on symbol " + std::to_string(symbol) +
                         " to follow to its limit point");
    steps.push_back(t);
    auto [it, fresh] = seen.emplace(t->target, path.size());
    path.push_back(t->target);
    if (fresh) continue;
    // Loop: steps[it->second .. end) returns to path[it->second].
    const size_t loop_start = it->second;
    SymbolLoop out;
    out.loop_state = path[loop_start];
    const int k = a.states[size_t(out.loop_state)].control_points, k0 = a.states[size_t(state)].control_points;
    out.loop = Eigen::MatrixXd::Identity(k, k);
    out.prefix = Eigen::MatrixXd::Identity(k0, k0);
    for (size_t s = loop_start; s < steps.size(); ++s) out.loop = out.loop * steps[s]->matrix;
    for (size_t s = 0; s < loop_start; ++s) out.prefix = out.prefix * steps[s]->matrix;
    return out;
  }
}

}  // namespace

Eigen::VectorXd limit_point(const Automaton& a, int state, int symbol) {
  const SymbolLoop way = follow_symbol(a, state, symbol);
  return way.prefix * fixed_point(way.loop);
}

FixedPointFrame fixed_point_frame(const Eigen::MatrixXd& m, int dimension, const Eigen::VectorXd& toward) {
  FixedPointFrame frame;
  frame.point = fixed_point(m);
  const Eigen::Index k = m.rows();
  if (dimension < 1 || dimension > 2 || k < dimension + 1) {
    frame.reason = "no tangents for an attractor of dimension " + std::to_string(dimension) + " on " +
                   std::to_string(k) + " control points";
    return frame;
  }
  // An orthonormal basis of the differences (vectors summing to 0): the complement of (1, ..., 1).
  const Eigen::MatrixXd ones = Eigen::MatrixXd::Ones(k, 1);
  const Eigen::MatrixXd basis = Eigen::HouseholderQR<Eigen::MatrixXd>(ones).householderQ();
  const Eigen::MatrixXd q = basis.rightCols(k - 1);
  const Eigen::MatrixXd restricted = q.transpose() * m * q;
  Eigen::EigenSolver<Eigen::MatrixXd> eigen(restricted);
  if (eigen.info() != Eigen::Success) {
    frame.reason = "the loop's eigenvalues did not converge";
    return frame;
  }
  std::vector<Eigen::Index> order(size_t(k - 1));
  for (Eigen::Index i = 0; i < k - 1; ++i) order[size_t(i)] = i;
  const Eigen::VectorXcd values = eigen.eigenvalues();
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return std::abs(values(a)) > std::abs(values(b)); });
  // A repeated (or defective) eigenvalue first: its numerical pair may carry a small imaginary part.
  const double tolerance = 1e-9 * (1 + std::abs(values(order[0])));
  if (Eigen::Index(dimension) < k - 1 &&
      std::abs(values(order[size_t(dimension)])) > std::abs(values(order[size_t(dimension - 1)])) * (1 - 1e-6)) {
    frame.reason = "the loop's eigenvalue " + std::to_string(dimension + 1) + " is as large as eigenvalue " +
                   std::to_string(dimension) + " (after 1): no single tangent " + std::string(dimension == 1 ? "line" : "plane");
    return frame;
  }
  for (int i = 0; i < dimension; ++i) {
    const std::complex<double> v = values(order[size_t(i)]);
    if (std::abs(v.imag()) > tolerance) {
      frame.reason = "the loop's eigenvalue " + std::to_string(i + 2) + " is complex: the attractor turns around the point";
      return frame;
    }
  }
  // Orientation: the components of (toward - point) along the eigenvectors.
  const Eigen::MatrixXcd vectors = eigen.eigenvectors();
  const Eigen::VectorXcd along = vectors.fullPivLu().solve((q.transpose() * (toward - frame.point)).cast<std::complex<double>>());
  for (int i = 0; i < dimension; ++i) {
    Eigen::VectorXd d = q * vectors.col(order[size_t(i)]).real();
    if (along(order[size_t(i)]).real() < 0) d = -d;
    frame.directions.push_back(d / d.norm());
    frame.rates.push_back(values(order[size_t(i)]).real());
  }
  frame.smooth = true;
  return frame;
}

FixedPointFrame limit_frame(const Automaton& a, int state, int symbol, int dimension, const Eigen::VectorXd& toward) {
  const SymbolLoop way = follow_symbol(a, state, symbol);
  // `toward` seen from the loop's state: its preimage is not needed, only an attractor point there on
  // the same side; the loop's own other end (the limit of another symbol) serves.
  Eigen::VectorXd toward_loop = toward;
  if (way.loop_state != state) {
    const std::vector<Transition>& out = a.transitions[size_t(way.loop_state)];
    toward_loop = limit_point(a, way.loop_state, (out.front().symbol == symbol ? out.back() : out.front()).symbol);
  }
  FixedPointFrame frame = fixed_point_frame(way.loop, dimension, toward_loop);
  frame.point = way.prefix * frame.point;
  for (Eigen::VectorXd& d : frame.directions) {
    d = way.prefix * d;
    d /= d.norm();
  }
  return frame;
}

void complete_primitives(Automaton& a) {
  for (size_t q = 0; q < a.states.size(); ++q) {
    State& s = a.states[q];
    if (s.vertices.size() > 0) continue;
    if (s.primitive == Primitive::kSegment && !a.transitions[q].empty()) {
      s.vertices.resize(s.control_points, 2);
      s.vertices.col(0) = limit_point(a, int(q), a.transitions[q].front().symbol);
      s.vertices.col(1) = limit_point(a, int(q), a.transitions[q].back().symbol);
      continue;
    }
    if (natural_vertex_count(s.primitive) == s.control_points) {
      s.vertices = Eigen::MatrixXd::Identity(s.control_points, s.control_points);
      continue;
    }
    throw InvalidInput(state_label(a, int(q)) + ": give the barycentric vertices of its " +
                       primitive_name(s.primitive) + " (they cannot be derived from " +
                       std::to_string(s.control_points) + " control points)");
  }
}

Automaton tensor_product(const Automaton& a_in, const Automaton& b_in) {
  Automaton a = a_in, b = b_in;
  complete_primitives(a);
  complete_primitives(b);
  Automaton out;
  out.alphabet_size = a.alphabet_size * b.alphabet_size;
  std::map<std::pair<int, int>, int> index;
  std::vector<std::pair<int, int>> queue{{a.initial, b.initial}};
  index[queue[0]] = 0;
  for (size_t i = 0; i < queue.size(); ++i) {
    auto [qa, qb] = queue[i];
    const State &sa = a.states[size_t(qa)], &sb = b.states[size_t(qb)];
    State s;
    s.name = (sa.name.empty() ? std::to_string(qa) : sa.name) + "x" + (sb.name.empty() ? std::to_string(qb) : sb.name);
    s.control_points = sa.control_points * sb.control_points;
    int da = primitive_dimension(sa.primitive), db = primitive_dimension(sb.primitive);
    if (sa.primitive == Primitive::kSegment && sb.primitive == Primitive::kSegment) {
      s.primitive = Primitive::kQuad;
      s.vertices.resize(s.control_points, 4);
      // Corners counter-clockwise in (u, v): (0,0), (1,0), (1,1), (0,1).
      const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (int c = 0; c < 4; ++c)
        s.vertices.col(c) = kronecker(sa.vertices.col(corner[c][0]), sb.vertices.col(corner[c][1]));
    } else if ((sa.primitive == Primitive::kQuad && sb.primitive == Primitive::kSegment)) {
      s.primitive = Primitive::kHexahedron;
      s.vertices.resize(s.control_points, 8);
      for (int w = 0; w < 2; ++w)
        for (int c = 0; c < 4; ++c) s.vertices.col(4 * w + c) = kronecker(sa.vertices.col(c), sb.vertices.col(w));
    } else {
      throw InvalidInput("a tensor product needs two curves (a surface) or a surface and a curve (a volume); got a " +
                         std::string(primitive_name(sa.primitive)) + " and a " + primitive_name(sb.primitive) +
                         " (dimensions " + std::to_string(da) + " and " + std::to_string(db) + ")");
    }
    out.states.push_back(s);
    out.transitions.emplace_back();
    for (const Transition& ta : a.transitions[size_t(qa)]) {
      for (const Transition& tb : b.transitions[size_t(qb)]) {
        std::pair<int, int> target{ta.target, tb.target};
        auto [it, fresh] = index.emplace(target, int(queue.size()));
        if (fresh) queue.push_back(target);
        out.transitions[i].push_back(
            Transition{ta.symbol * b.alphabet_size + tb.symbol, it->second, kronecker(ta.matrix, tb.matrix)});
      }
    }
  }
  out.initial = 0;
  return out;
}

Automaton restrict_words(const Automaton& a_in, const Automaton& pattern) {
  // End points and corners come from the whole automaton, before words are taken away.
  Automaton a = a_in;
  complete_primitives(a);
  if (a.alphabet_size != pattern.alphabet_size)
    throw InvalidInput("the pattern's alphabet has " + std::to_string(pattern.alphabet_size) +
                       " symbols, the automaton's " + std::to_string(a.alphabet_size));
  Automaton out;
  out.alphabet_size = a.alphabet_size;
  std::map<std::pair<int, int>, int> index;
  std::vector<std::pair<int, int>> queue{{a.initial, pattern.initial}};
  index[queue[0]] = 0;
  for (size_t i = 0; i < queue.size(); ++i) {
    auto [q, p] = queue[i];
    State s = a.states[size_t(q)];
    if (pattern.states.size() > 1) s.name += "/" + std::to_string(p);
    out.states.push_back(s);
    out.transitions.emplace_back();
    for (const Transition& t : a.transitions[size_t(q)]) {
      const Transition* allowed = find_transition(pattern, p, t.symbol);
      if (!allowed) continue;
      std::pair<int, int> target{t.target, allowed->target};
      auto [it, fresh] = index.emplace(target, int(queue.size()));
      if (fresh) queue.push_back(target);
      out.transitions[i].push_back(Transition{t.symbol, it->second, t.matrix});
    }
  }
  return out;
}

}  // namespace cifs
}  // namespace lacuna
