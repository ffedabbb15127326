#include "cifs/library.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>

#include "cifs/nurbs.h"
#include "errors.h"
#include "util/suggest.h"

namespace lacuna {
namespace cifs {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Barycentric coordinates over the frame (origin, e1, e2[, e3]) of a point of the plane or space.
Eigen::VectorXd frame_coordinates(const Eigen::VectorXd& p) {
  Eigen::VectorXd b(p.size() + 1);
  b(0) = 1 - p.sum();
  b.tail(p.size()) = p;
  return b;
}

// The barycentric matrix over the frame of the affine map x -> L x + t.
Eigen::MatrixXd affine_matrix(const Eigen::MatrixXd& linear, const Eigen::VectorXd& translation) {
  const Eigen::Index n = linear.rows();
  Eigen::MatrixXd m(n + 1, n + 1);
  m.col(0) = frame_coordinates(translation);
  for (Eigen::Index j = 0; j < n; ++j) m.col(j + 1) = frame_coordinates(linear.col(j) + translation);
  return m;
}

Eigen::MatrixXd frame_points(int n) {
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(3, n + 1);
  for (int j = 0; j < n; ++j) p(j, j + 1) = 1;
  return p;
}

// One-state automaton with the given maps (symbols in order).
Automaton single_state(const std::string& name, int k, Primitive primitive, const std::vector<Eigen::MatrixXd>& maps,
                       const Eigen::MatrixXd& vertices = Eigen::MatrixXd()) {
  Automaton a;
  State s;
  s.name = name;
  s.control_points = k;
  s.primitive = primitive;
  s.vertices = vertices;
  a.states.push_back(s);
  a.transitions.emplace_back();
  for (size_t i = 0; i < maps.size(); ++i) a.transitions[0].push_back(Transition{int(i), 0, maps[i]});
  a.alphabet_size = int(maps.size());
  complete_primitives(a);
  return a;
}

// Vertices of the unit square or cube over the frame: (0,0) (1,0) (1,1) (0,1) [then z = 1].
Eigen::MatrixXd unit_box_vertices(int n) {
  const int corners = n == 2 ? 4 : 8;
  const int xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  Eigen::MatrixXd v(n + 1, corners);
  for (int c = 0; c < corners; ++c) {
    Eigen::VectorXd p(n);
    p(0) = xy[c % 4][0];
    p(1) = xy[c % 4][1];
    if (n == 3) p(2) = c / 4;
    v.col(c) = frame_coordinates(p);
  }
  return v;
}

// Homotheties of ratio 1/2 towards each control point (the control points are the simplex).
Cifs sierpinski(int k, const std::string& name, Primitive primitive, const Eigen::MatrixXd& points) {
  std::vector<Eigen::MatrixXd> maps;
  for (int i = 0; i < k; ++i) {
    Eigen::MatrixXd m = 0.5 * Eigen::MatrixXd::Identity(k, k);
    m.row(i).array() += 0.5;
    maps.push_back(m);
  }
  return Cifs{name, single_state(name, k, primitive, maps), points, false};
}

// Maps of ratio 1/3 onto the sub-boxes (i, j[, l]) of a 3 x 3 [x 3] split that `keep` accepts.
Cifs thirds(int n, const std::string& name, const std::function<bool(int, int, int)>& keep) {
  std::vector<Eigen::MatrixXd> maps;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int l = 0; l < (n == 3 ? 3 : 1); ++l) {
        if (!keep(i, j, l)) continue;
        Eigen::VectorXd t(n);
        t(0) = i / 3.0;
        t(1) = j / 3.0;
        if (n == 3) t(2) = l / 3.0;
        maps.push_back(affine_matrix(Eigen::MatrixXd::Identity(n, n) / 3.0, t));
      }
  Primitive primitive = n == 2 ? Primitive::kQuad : Primitive::kHexahedron;
  return Cifs{name, single_state(name, n + 1, primitive, maps, unit_box_vertices(n)), frame_points(n), false};
}

Cifs koch() {
  const double c = std::cos(kPi / 3) / 3, s = std::sin(kPi / 3) / 3;
  Eigen::Matrix2d scale = Eigen::Matrix2d::Identity() / 3, up, down;
  up << c, -s, s, c;
  down << c, s, -s, c;
  std::vector<Eigen::MatrixXd> maps = {affine_matrix(scale, Eigen::Vector2d(0, 0)),
                                       affine_matrix(up, Eigen::Vector2d(1.0 / 3, 0)),
                                       affine_matrix(down, Eigen::Vector2d(0.5, std::sqrt(3.0) / 6)),
                                       affine_matrix(scale, Eigen::Vector2d(2.0 / 3, 0))};
  return Cifs{"koch_curve", single_state("koch_curve", 3, Primitive::kSegment, maps), frame_points(2), false};
}

// The Takagi (blancmange) curve T(x) = sum s(2^n x) / 2^n over [0, 1], s the distance to the
// nearest integer: T(x/2) = x/2 + T(x)/2 and T((x+1)/2) = (1-x)/2 + T(x)/2.
Cifs takagi() {
  Eigen::Matrix2d left, right;
  left << 0.5, 0, 0.5, 0.5;
  right << 0.5, 0, -0.5, 0.5;
  std::vector<Eigen::MatrixXd> maps = {affine_matrix(left, Eigen::Vector2d(0, 0)),
                                       affine_matrix(right, Eigen::Vector2d(0.5, 0.5))};
  return Cifs{"takagi_curve", single_state("takagi_curve", 3, Primitive::kSegment, maps), frame_points(2), false};
}

Cifs uniform_bspline(int degree, const std::string& name) {
  std::vector<double> knots;
  for (int i = 0; i < 2 * degree; ++i) knots.push_back(i);
  Cifs c{name, nurbs_automaton(degree, knots).automaton, Eigen::MatrixXd::Zero(3, degree + 1), false};
  for (int i = 0; i <= degree; ++i) c.control_points.col(i) << i, (i % 2) ? 1.0 : 0.0, 0;
  return c;
}

const std::map<std::string, std::function<Cifs()>>& library() {
  static const std::map<std::string, std::function<Cifs()>> systems = {
      {"sierpinski_triangle",
       [] {
         Eigen::MatrixXd p(3, 3);
         p << 0, 1, 0.5, 0, 0, std::sqrt(3.0) / 2, 0, 0, 0;
         return sierpinski(3, "sierpinski_triangle", Primitive::kTriangle, p);
       }},
      {"sierpinski_tetrahedron",
       [] {
         Eigen::MatrixXd p(3, 4);
         p << 0, 1, 0.5, 0.5, 0, 0, std::sqrt(3.0) / 2, std::sqrt(3.0) / 6, 0, 0, 0, std::sqrt(2.0 / 3.0);
         return sierpinski(4, "sierpinski_tetrahedron", Primitive::kTetrahedron, p);
       }},
      {"menger_sponge",
       [] { return thirds(3, "menger_sponge", [](int i, int j, int l) { return (i == 1) + (j == 1) + (l == 1) < 2; }); }},
      {"cantor_dust_2d", [] { return thirds(2, "cantor_dust_2d", [](int i, int j, int) { return i != 1 && j != 1; }); }},
      {"cantor_dust_3d",
       [] { return thirds(3, "cantor_dust_3d", [](int i, int j, int l) { return i != 1 && j != 1 && l != 1; }); }},
      {"koch_curve", koch},
      {"takagi_curve", takagi},
      {"bspline_quadratic", [] { return uniform_bspline(2, "bspline_quadratic"); }},
      {"bspline_cubic", [] { return uniform_bspline(3, "bspline_cubic"); }},
  };
  return systems;
}

}  // namespace

std::vector<std::string> library_names() {
  std::vector<std::string> names;
  for (const auto& entry : library()) names.push_back(entry.first);
  return names;
}

Cifs library_system(const std::string& name) {
  auto it = library().find(name);
  if (it == library().end()) {
    std::string message = "unknown system \"" + name + "\"" + did_you_mean(name, library_names());
    message += " (shipped:";
    for (const std::string& n : library_names()) message += " " + n;
    throw InvalidInput(message + ")");
  }
  return it->second();
}

}  // namespace cifs
}  // namespace lacuna
