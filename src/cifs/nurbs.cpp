#include "cifs/nurbs.h"

#include <cmath>
#include <map>
#include <string>

#include "errors.h"

namespace lacuna {
namespace cifs {
namespace {

void check_knots(int degree, const std::vector<double>& knots) {
  if (degree < 1 || degree > 12) throw InvalidInput("degree must be from 1 to 12, got " + std::to_string(degree));
  if (knots.size() != size_t(2 * degree))
    throw InvalidInput("a piece of degree " + std::to_string(degree) + " needs " + std::to_string(2 * degree) +
                       " knots t0 .. t" + std::to_string(2 * degree - 1) + ", got " + std::to_string(knots.size()));
  for (size_t i = 0; i < knots.size(); ++i) {
    if (!std::isfinite(knots[i])) throw InvalidInput("knot " + std::to_string(i) + " is not finite");
    if (i > 0 && knots[i] < knots[i - 1])
      throw InvalidInput("knots must not decrease (t" + std::to_string(i) + " < t" + std::to_string(i - 1) + ")");
  }
  if (!(knots[size_t(degree)] > knots[size_t(degree - 1)]))
    throw InvalidInput("the piece's own interval [t" + std::to_string(degree - 1) + ", t" + std::to_string(degree) +
                       "] is empty");
  // De Boor's recursion divides by t(i+d-r) - t(i-1) for the spans around the piece; they must
  // not vanish (at most d equal knots on either side of the interval).
  for (int i = 1; i <= degree; ++i)
    if (!(knots[size_t(i + degree - 1)] > knots[size_t(i - 1)]))
      throw InvalidInput("knots t" + std::to_string(i - 1) + " .. t" + std::to_string(i + degree - 1) +
                         " are all equal; a knot may repeat at most d times around the piece");
}

std::vector<double> knots_from_window(const std::vector<double>& window) {
  std::vector<double> t(window.size() + 1, 0.0);
  for (size_t i = 0; i < window.size(); ++i) t[i + 1] = t[i] + window[i];
  return t;
}

}  // namespace

Eigen::VectorXd blossom_weights(int degree, const std::vector<double>& t, const std::vector<double>& x) {
  const int d = degree;
  std::vector<Eigen::VectorXd> q(size_t(d) + 1);
  for (int i = 0; i <= d; ++i) q[size_t(i)] = Eigen::VectorXd::Unit(d + 1, i);
  for (int r = 1; r <= d; ++r) {
    const double xr = x[size_t(r - 1)];
    for (int i = d; i >= r; --i) {
      const double hi = t[size_t(i + d - r)], lo = t[size_t(i - 1)];
      q[size_t(i)] = ((hi - xr) * q[size_t(i - 1)] + (xr - lo) * q[size_t(i)]) / (hi - lo);
    }
  }
  return q[size_t(d)];
}

NurbsAutomaton nurbs_automaton(int degree, const std::vector<double>& knots) {
  check_knots(degree, knots);
  const int d = degree, n = 2 * d - 1;
  NurbsAutomaton out;
  std::vector<double> first(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) first[size_t(i)] = knots[size_t(i + 1)] - knots[size_t(i)];
  std::map<std::vector<double>, int> index{{first, 0}};
  out.windows.push_back(first);
  for (size_t s = 0; s < out.windows.size(); ++s) {
    const std::vector<double> window = out.windows[s];
    // Mid-knot insertion: every inter-node read twice; the halves are windows of it.
    std::vector<double> w;
    for (double u : window) {
      w.push_back(u);
      w.push_back(u);
    }
    const std::vector<double> t = knots_from_window(window);
    std::vector<double> refined;  // t0, m0, t1, m1, ..., t(2d-1)
    for (size_t i = 0; i < t.size(); ++i) {
      refined.push_back(t[i]);
      if (i + 1 < t.size()) refined.push_back(0.5 * (t[i] + t[i + 1]));
    }
    State state;
    state.name = "s" + std::to_string(s);
    state.control_points = d + 1;
    state.primitive = Primitive::kSegment;
    out.automaton.states.push_back(state);
    out.automaton.transitions.emplace_back();
    for (int side = 0; side < 2; ++side) {
      // Left child: W(n-d+1 .. n+d-1), right child: W(n-d+2 .. n+d) (1-based).
      std::vector<double> child(w.begin() + (n - d + side), w.begin() + (n - d + side) + n);
      // Its knots in the parent's parameter: refined(d-1+side .. 3d-2+side).
      std::vector<double> child_knots(refined.begin() + (d - 1 + side), refined.begin() + (3 * d - 1 + side));
      Eigen::MatrixXd m(d + 1, d + 1);
      for (int j = 0; j <= d; ++j) {
        std::vector<double> args(child_knots.begin() + j, child_knots.begin() + j + d);
        m.col(j) = blossom_weights(d, t, args);
      }
      auto [it, fresh] = index.emplace(child, int(out.windows.size()));
      if (fresh) out.windows.push_back(child);
      out.automaton.transitions[s].push_back(Transition{side, it->second, m});
    }
  }
  out.automaton.alphabet_size = 2;
  out.automaton.initial = 0;
  complete_primitives(out.automaton);
  return out;
}

double nurbs_vertex_parameter(int degree, const std::vector<double>& knots, int level, uint64_t vertex) {
  const double lo = knots[size_t(degree - 1)], hi = knots[size_t(degree)];
  return lo + (hi - lo) * (double(vertex) / std::ldexp(1.0, level));
}

}  // namespace cifs
}  // namespace lacuna
