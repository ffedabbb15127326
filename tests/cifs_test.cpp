// The CIFS engine, NURBS automata and shipped systems against known values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "cifs/automaton.h"
#include "cifs/junction.h"
#include "cifs/library.h"
#include "cifs/support.h"
#include "cifs/nurbs.h"
#include "cifs/tessellate.h"
#include "errors.h"
#include "recipe/cifs_system.h"

namespace lacuna {
namespace cifs {
namespace {

// Cox-de Boor: the B-spline basis of degree d on knot vector u at parameter x (x in
// [u[d], u[n+1]) with n + 1 = number of basis functions), evaluated by the textbook recursion.
std::vector<double> basis(int d, const std::vector<double>& u, double x) {
  const int n = int(u.size()) - d - 2;
  std::vector<double> b(u.size() - 1, 0.0);
  // Degree 0: the span containing x (the last span closed at its right end).
  for (size_t i = 0; i + 1 < u.size(); ++i)
    if (u[i] < u[i + 1] && ((x >= u[i] && x < u[i + 1]) || (x == u[size_t(n + 1)] && u[i + 1] == u[size_t(n + 1)])))
      b[i] = 1;
  for (int p = 1; p <= d; ++p)
    for (size_t i = 0; i + size_t(p) + 1 < u.size(); ++i) {
      double left = u[i + size_t(p)] > u[i] ? (x - u[i]) / (u[i + size_t(p)] - u[i]) * b[i] : 0;
      double right = u[i + size_t(p) + 1] > u[i + 1] ? (u[i + size_t(p) + 1] - x) / (u[i + size_t(p) + 1] - u[i + 1]) * b[i + 1] : 0;
      b[i] = left + right;
    }
  b.resize(size_t(n) + 1);
  return b;
}

// The piece with local knots t0 .. t(2d-1) evaluated at x by Cox-de Boor on the knot vector
// extended by one knot at each end (which does not change the piece).
Eigen::Vector3d de_boor_point(int d, const std::vector<double>& t, const Eigen::MatrixXd& points, bool rational, double x) {
  std::vector<double> u{t.front() - 1};
  u.insert(u.end(), t.begin(), t.end());
  u.push_back(t.back() + 1);
  std::vector<double> b = basis(d, u, x);
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (int i = 0; i <= d; ++i) {
    Eigen::Vector4d p;
    if (rational) p = points.col(i);  // homogeneous
    else p << points.col(i), 1.0;
    sum += b[size_t(i)] * p;
  }
  return sum.head<3>() / sum(3);
}

Cifs nurbs_cifs(int d, const std::vector<double>& knots, const Eigen::MatrixXd& points, bool rational) {
  return Cifs{"nurbs", nurbs_automaton(d, knots).automaton, points, rational};
}

TEST(Nurbs, QuadraticMatricesMatchTheClosedFormsAndChaikin) {
  const double u1 = 0.7, u2 = 1.9, u3 = 0.35;
  NurbsAutomaton na = nurbs_automaton(2, {0, u1, u1 + u2, u1 + u2 + u3});
  const Eigen::MatrixXd& ml = find_transition(na.automaton, 0, 0)->matrix;
  const Eigen::MatrixXd& mr = find_transition(na.automaton, 0, 1)->matrix;
  Eigen::Matrix3d el, er;
  const double a = 2 * (u1 + u2), b = 2 * (u2 + u3);
  el << (u1 + 2 * u2) / a, u2 / a, 0, u1 / a, (2 * u1 + u2) / a, (u2 + 2 * u3) / b, 0, 0, u2 / b;
  er << u2 / a, 0, 0, (2 * u1 + u2) / a, (u2 + 2 * u3) / b, u3 / b, 0, u2 / b, (2 * u2 + u3) / b;
  EXPECT_LT((ml - el).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((mr - er).cwiseAbs().maxCoeff(), 1e-14);
  // Start and end points: the fixed points of L and R.
  Eigen::Vector3d start(u2 / (u1 + u2), u1 / (u1 + u2), 0), end(0, u3 / (u2 + u3), u2 / (u2 + u3));
  EXPECT_LT((na.automaton.states[0].vertices.col(0) - start).norm(), 1e-14);
  EXPECT_LT((na.automaton.states[0].vertices.col(1) - end).norm(), 1e-14);
  // Equal inter-nodes: Chaikin's corner cutting, one uniform state.
  NurbsAutomaton uniform = nurbs_automaton(2, {0, 1, 2, 3});
  ASSERT_EQ(uniform.automaton.states.size(), 1u);
  Eigen::Matrix3d chaikin_l, chaikin_r;
  chaikin_l << 0.75, 0.25, 0, 0.25, 0.75, 0.75, 0, 0, 0.25;
  chaikin_r << 0.25, 0, 0, 0.75, 0.75, 0.25, 0, 0.25, 0.75;
  EXPECT_LT((find_transition(uniform.automaton, 0, 0)->matrix - chaikin_l).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT((find_transition(uniform.automaton, 0, 1)->matrix - chaikin_r).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Nurbs, StateCountsFromGenericKnots) {
  for (int d = 2; d <= 5; ++d) {
    std::vector<double> knots{0};
    for (int i = 1; i < 2 * d; ++i) knots.push_back(knots.back() + 0.3 + 0.17 * i * i);  // distinct inter-nodes
    NurbsAutomaton na = nurbs_automaton(d, knots);
    EXPECT_EQ(na.automaton.states.size(), size_t(4 * (d - 1))) << "degree " << d;
    EXPECT_EQ(stationary_states(na.automaton).size(), 3u) << "degree " << d;
  }
}

// Pairs reachable in a product are the pairs of states reachable in the same number of steps.
size_t product_states_by_levels(const Automaton& a, const Automaton& b) {
  std::set<std::pair<int, int>> pairs;
  std::set<int> ra{a.initial}, rb{b.initial};
  for (int level = 0; level < 64; ++level) {
    for (int x : ra)
      for (int y : rb) pairs.insert({x, y});
    std::set<int> na, nb;
    for (int x : ra)
      for (const Transition& t : a.transitions[size_t(x)]) na.insert(t.target);
    for (int y : rb)
      for (const Transition& t : b.transitions[size_t(y)]) nb.insert(t.target);
    ra = na;
    rb = nb;
  }
  return pairs.size();
}

TEST(Nurbs, TensorProductStateCounts) {
  Automaton quadratic = nurbs_automaton(2, {0, 0.5, 1.7, 2.0}).automaton;
  Automaton cubic = nurbs_automaton(3, {0, 0.4, 1.1, 2.3, 2.6, 3.9}).automaton;
  Automaton biquadratic = tensor_product(quadratic, quadratic);
  // Initial pair, then {L, R} x {L, R}, then {L, R, U} x {L, R, U}: 1 + 9.
  EXPECT_EQ(biquadratic.states.size(), 10u);
  EXPECT_EQ(biquadratic.states.size(), product_states_by_levels(quadratic, quadratic));
  Automaton bicubic = tensor_product(cubic, cubic);
  EXPECT_EQ(bicubic.states.size(), product_states_by_levels(cubic, cubic));
  EXPECT_EQ(biquadratic.alphabet_size, 4);
  for (const auto& list : bicubic.transitions) EXPECT_EQ(list.size(), 4u);
  EXPECT_EQ(bicubic.states[0].control_points, 16);
  EXPECT_EQ(bicubic.states[0].primitive, Primitive::kQuad);
}

void expect_matches_cox_de_boor(int d, const std::vector<double>& knots, const Eigen::MatrixXd& points, bool rational,
                                int level) {
  Cifs c = nurbs_cifs(d, knots, points, rational);
  std::vector<std::vector<Vec3d>> lines = tessellate_curves(c, level);
  ASSERT_EQ(lines.size(), 1u);
  ASSERT_EQ(lines[0].size(), (size_t(1) << level) + 1);
  double size = 0;
  for (Eigen::Index i = 0; i < points.cols(); ++i)
    for (Eigen::Index j = 0; j < points.cols(); ++j) {
      Eigen::Vector3d a = points.col(i).head<3>() / (rational ? points(3, i) : 1.0);
      Eigen::Vector3d b = points.col(j).head<3>() / (rational ? points(3, j) : 1.0);
      size = std::max(size, (a - b).norm());
    }
  double worst = 0;
  for (size_t v = 0; v < lines[0].size(); ++v) {
    double x = nurbs_vertex_parameter(d, knots, level, v);
    Eigen::Vector3d expected = de_boor_point(d, knots, points, rational, x);
    const Vec3d& got = lines[0][v];
    worst = std::max(worst, (Eigen::Vector3d(got.x, got.y, got.z) - expected).norm());
  }
  EXPECT_LT(worst, 1e-9 * size) << "degree " << d << (rational ? " rational" : "");
}

TEST(Nurbs, TessellationVerticesEqualCoxDeBoor) {
  for (int d = 2; d <= 5; ++d) {
    Eigen::MatrixXd points(3, d + 1), homogeneous(4, d + 1);
    for (int i = 0; i <= d; ++i) {
      points.col(i) << 10 * std::cos(0.9 * i), 7 * std::sin(1.3 * i) + i, 3.0 * i * i / (d + 1);
      double w = 0.5 + 0.4 * (i % 3) + 0.3 * i;
      homogeneous.col(i) << w * points.col(i), w;
    }
    std::vector<double> uniform, skewed{0};
    for (int i = 0; i < 2 * d; ++i) uniform.push_back(i);
    for (int i = 1; i < 2 * d; ++i) skewed.push_back(skewed.back() + (i % 2 ? 0.01 : 5.0) * (1 + 0.3 * i));
    expect_matches_cox_de_boor(d, uniform, points, false, 7);
    expect_matches_cox_de_boor(d, skewed, points, false, 7);
    expect_matches_cox_de_boor(d, skewed, homogeneous, true, 7);
    expect_matches_cox_de_boor(d, uniform, homogeneous, true, 5);
  }
}

// The unit derivative of the piece at x by second-order differences (one-sided at its ends).
Eigen::Vector3d cox_de_boor_direction(int d, const std::vector<double>& knots, const Eigen::MatrixXd& points,
                                      bool rational, double x) {
  const double span = knots[size_t(d)] - knots[size_t(d - 1)], h = 1e-5 * span;
  auto p = [&](double t) { return de_boor_point(d, knots, points, rational, t); };
  Eigen::Vector3d v;
  if (x - h < knots[size_t(d - 1)]) v = -3 * p(x) + 4 * p(x + h) - p(x + 2 * h);
  else if (x + h > knots[size_t(d)]) v = 3 * p(x) - 4 * p(x - h) + p(x - 2 * h);
  else v = p(x + h) - p(x - h);
  return v / v.norm();
}

TEST(Nurbs, LimitTangentsEqualTheCoxDeBoorDerivative) {
  for (int d = 2; d <= 4; ++d) {
    Eigen::MatrixXd points(3, d + 1), homogeneous(4, d + 1);
    for (int i = 0; i <= d; ++i) {
      points.col(i) << 10 * std::cos(0.9 * i), 7 * std::sin(1.3 * i) + i, 3.0 * i * i / (d + 1);
      const double w = 0.5 + 0.4 * (i % 3) + 0.3 * i;
      homogeneous.col(i) << w * points.col(i), w;
    }
    std::vector<double> uniform, skewed{0};
    for (int i = 0; i < 2 * d; ++i) uniform.push_back(i);
    for (int i = 1; i < 2 * d; ++i) skewed.push_back(skewed.back() + (i % 2 ? 0.3 : 2.0) * (1 + 0.3 * i));
    for (const auto& knots : {uniform, skewed})
      for (bool rational : {false, true}) {
        Cifs c = nurbs_cifs(d, knots, rational ? homogeneous : points, rational);
        complete_primitives(c.automaton);
        const nlohmann::json frames = initial_frames_json(c);
        ASSERT_EQ(frames.size(), 2u);
        // Into the piece: along the parameter at its start, against it at its end.
        const Eigen::Vector3d start = cox_de_boor_direction(d, knots, c.control_points, rational, knots[size_t(d - 1)]);
        const Eigen::Vector3d end = cox_de_boor_direction(d, knots, c.control_points, rational, knots[size_t(d)]);
        for (int i = 0; i < 3; ++i) {
          ASSERT_TRUE(frames[0]["smooth"].get<bool>()) << frames[0].dump();
          EXPECT_NEAR(frames[0]["tangents"][0][i].get<double>(), start(i), 1e-6) << "degree " << d;
          EXPECT_NEAR(frames[1]["tangents"][0][i].get<double>(), -end(i), 1e-6) << "degree " << d;
        }
        // The rate: the second eigenvalue of a half's matrix, 1/2 for every B-spline.
        EXPECT_NEAR(frames[0]["rates"][0].get<double>(), 0.5, 1e-9);
      }
  }
}

TEST(Nurbs, PlanarTensorSurfaceHasTheNormalOfItsPlane) {
  const NurbsAutomaton u = nurbs_automaton(2, {0, 1, 2.5, 3}), v = nurbs_automaton(3, {0, 0.5, 1, 2, 2.2, 4});
  Cifs c{"patch", tensor_product(u.automaton, v.automaton), Eigen::MatrixXd(3, 3 * 4), false};
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 4; ++b) c.control_points.col(a * 4 + b) << 3.0 * a + 0.4 * b * b, 2.0 * b - 0.3 * a, 0;
  // Tilt the plane: z = 0.5 x - 0.25 y, normal (0.5, -0.25, -1) normalised up to its sign.
  c.control_points.row(2) = 0.5 * c.control_points.row(0) - 0.25 * c.control_points.row(1);
  complete_primitives(c.automaton);
  const nlohmann::json frames = initial_frames_json(c);
  ASSERT_EQ(frames.size(), 4u);
  const Eigen::Vector3d expected = Eigen::Vector3d(0.5, -0.25, -1).normalized();
  for (const auto& f : frames) {
    ASSERT_TRUE(f["smooth"].get<bool>()) << f.dump();
    const Eigen::Vector3d n(f["normal"][0].get<double>(), f["normal"][1].get<double>(), f["normal"][2].get<double>());
    EXPECT_NEAR(std::abs(n.dot(expected)), 1, 1e-9) << f.dump();
  }
}

TEST(Nurbs, RejectsBadKnots) {
  EXPECT_THROW(nurbs_automaton(2, {0, 1, 2}), InvalidInput);
  EXPECT_THROW(nurbs_automaton(2, {0, 2, 1, 3}), InvalidInput);
  EXPECT_THROW(nurbs_automaton(2, {0, 1, 1, 2}), InvalidInput);  // empty own interval
  EXPECT_THROW(nurbs_automaton(0, {}), InvalidInput);
}

TEST(Library, PieceCountsFromTheDefinitions) {
  EXPECT_EQ(count_pieces(library_system("menger_sponge").automaton, 3), 8000u);
  EXPECT_EQ(count_pieces(library_system("menger_sponge").automaton, 5), 3200000u);
  EXPECT_EQ(count_pieces(library_system("cantor_dust_2d").automaton, 4), 256u);
  EXPECT_EQ(count_pieces(library_system("cantor_dust_3d").automaton, 3), 512u);
  EXPECT_EQ(count_pieces(library_system("sierpinski_triangle").automaton, 6), 729u);
  EXPECT_EQ(count_pieces(library_system("sierpinski_tetrahedron").automaton, 4), 256u);
  // Enumerated pieces agree with the count.
  uint64_t n = 0;
  for_each_piece(library_system("cantor_dust_3d"), 3, [&](const Piece&) { ++n; });
  EXPECT_EQ(n, 512u);
}

TEST(Library, KochCurveLengthAndEnds) {
  std::vector<std::vector<Vec3d>> lines = tessellate_curves(library_system("koch_curve"), 5);
  ASSERT_EQ(lines.size(), 1u);
  ASSERT_EQ(lines[0].size(), 1025u);
  double length = 0;
  for (size_t i = 1; i < lines[0].size(); ++i) length += norm(lines[0][i] - lines[0][i - 1]);
  EXPECT_NEAR(length, std::pow(4.0 / 3.0, 5), 1e-12);
  EXPECT_LT(norm(lines[0].front() - Vec3d{0, 0, 0}), 1e-15);
  EXPECT_LT(norm(lines[0].back() - Vec3d{1, 0, 0}), 1e-14);
  // The apex of the first level's bump.
  EXPECT_LT(norm(tessellate_curves(library_system("koch_curve"), 1)[0][2] - Vec3d{0.5, std::sqrt(3.0) / 6, 0}), 1e-15);
}

TEST(Library, TakagiVerticesAreTheSeriesAtDyadicPoints) {
  const int level = 8;
  std::vector<std::vector<Vec3d>> lines = tessellate_curves(library_system("takagi_curve"), level);
  ASSERT_EQ(lines[0].size(), (1u << level) + 1);
  for (size_t i = 0; i < lines[0].size(); ++i) {
    double x = double(i) / (1 << level), t = 0;
    for (int n = 0; n <= level; ++n) {  // s(2^n x) vanishes beyond n = level at dyadic x
      double y = std::ldexp(x, n);
      t += std::fabs(y - std::round(y)) / std::ldexp(1.0, n);
    }
    EXPECT_NEAR(lines[0][i].x, x, 1e-14);
    EXPECT_NEAR(lines[0][i].y, t, 1e-14);
  }
}

TEST(Library, LacunarRestrictionDropsOneChildPerLevel) {
  nlohmann::json spec = {{"restrict", {{"nurbs_surface", {{"u", {{"degree", 2}, {"knots", {0, 1, 2, 3}}}},
                                                          {"v", {{"degree", 2}, {"knots", {0, 1, 2, 3}}}}}},
                                       {"control_points_mm",
                                        {{{0, 0, 0}, {0, 5, 1}, {0, 10, 0}},
                                         {{5, 0, 1}, {5, 5, 2}, {5, 10, 1}},
                                         {{10, 0, 0}, {10, 5, 1}, {10, 10, 0}}}}}},
                         {"drop_symbols", {3}}};
  Cifs c = parse_system(spec, "test", "system");
  EXPECT_EQ(count_pieces(c.automaton, 5), 243u);
  TriMesh mesh = tessellate_surface(c, 5);
  EXPECT_EQ(mesh.triangles.size(), 2u * 243u);
}

TEST(Library, FixedPointsAndValidation) {
  Eigen::Matrix3d m;
  m << 0.5, 0, 0, 0.5, 1, 0.5, 0, 0, 0.5;  // homothety towards control point 1
  Eigen::VectorXd x = fixed_point(m);
  EXPECT_LT((x - Eigen::Vector3d(0, 1, 0)).norm(), 1e-14);
  Automaton bad = library_system("sierpinski_triangle").automaton;
  bad.transitions[0][1].matrix(0, 0) += 0.1;
  EXPECT_THROW(validate(bad), InvalidInput);
  EXPECT_THROW(library_system("menger_spnge"), InvalidInput);
  try {
    library_system("menger_spnge");
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean \"menger_sponge\""), std::string::npos);
  }
}

TEST(Library, ExplicitAutomatonFromJson) {
  // The uniform quadratic B-spline written out by hand: two Chaikin maps on one state.
  nlohmann::json spec = {
      {"states", {{{"name", "u"}, {"control_points", 3}, {"primitive", "segment"}}}},
      {"transitions",
       {{{"from", "u"}, {"symbol", 0}, {"to", "u"}, {"matrix", {{0.75, 0.25, 0}, {0.25, 0.75, 0.75}, {0, 0, 0.25}}}},
        {{"from", "u"}, {"symbol", 1}, {"to", "u"}, {"matrix", {{0.25, 0, 0}, {0.75, 0.75, 0.25}, {0, 0.25, 0.75}}}}}},
      {"control_points_mm", {{0, 0, 0}, {1, 2, 0}, {2, 0, 0}}}};
  Cifs c = parse_system(spec, "test", "system");
  std::vector<std::vector<Vec3d>> lines = tessellate_curves(c, 4);
  // Ends of the uniform quadratic piece: the midpoints of the first and last legs.
  EXPECT_LT(norm(lines[0].front() - Vec3d{0.5, 1, 0}), 1e-14);
  EXPECT_LT(norm(lines[0].back() - Vec3d{1.5, 1, 0}), 1e-14);
  nlohmann::json broken = spec;
  broken["transitions"][0]["matrix"][0][0] = 0.7;
  EXPECT_THROW(parse_system(broken, "test", "system"), InvalidInput);
}

}  // namespace
}  // namespace cifs
}  // namespace lacuna

namespace lacuna {
namespace cifs {
namespace {

// A bi-quadratic NURBS patch A (non-uniform knots in u) and a NURBS x Takagi patch B sharing A's u
// automaton, B 4 mm beyond A's v = 1 border, both wavy in z.
struct JunctionSides {
  TensorSurface a, b;
};

JunctionSides junction_sides() {
  JunctionSides s;
  s.a.u = nurbs_automaton(2, {0, 1, 3, 4}).automaton;
  s.a.v = nurbs_automaton(2, {0, 1, 2, 3}).automaton;
  s.b.u = s.a.u;
  s.b.v = library_system("takagi_curve").automaton;
  s.a.control_points.resize(3, 9);
  s.b.control_points.resize(3, 9);
  for (int i = 0; i < 3; ++i)
    for (int l = 0; l < 3; ++l) {
      s.a.control_points.col(i * 3 + l) << 6.0 * i, 5.0 * l, (i + l) % 2 ? 1.5 : -0.5;
      // The Takagi frame (origin, e1, e2): the curve runs from the origin to e1, e2 lifts it.
      const Eigen::Vector3d origin(6.0 * i, 14, 0.5 * i);
      const Eigen::Vector3d lift = l == 2 ? Eigen::Vector3d(0, 0, 3) : Eigen::Vector3d(0, 0, 0);
      s.b.control_points.col(i * 3 + l) = origin + (l == 1 ? Eigen::Vector3d(0, 10, 0) : Eigen::Vector3d(0, 0, 0)) + lift;
    }
  return s;
}

// Per word of u symbols, the two corners of the level's piece whose v symbols are all `v_symbol`
// (its first v symbol `first`), at the border v = `border` (0: corners 0, 1; 1: corners 3, 2).
std::map<std::vector<int>, std::pair<Eigen::Vector3d, Eigen::Vector3d>> border_pieces(const Cifs& c, int level, int v_alphabet,
                                                                                    int first, int v_symbol, int border) {
  std::map<std::vector<int>, std::pair<Eigen::Vector3d, Eigen::Vector3d>> out;
  for_each_piece(c, level, [&](const Piece& p) {
    std::vector<int> u;
    for (size_t i = 0; i < p.word->size(); ++i) {
      const int v = (*p.word)[i] % v_alphabet;
      if (v != (i == 0 ? first : v_symbol)) return;
      u.push_back((*p.word)[i] / v_alphabet);
    }
    const Eigen::Matrix3Xd& x = *p.vertices;
    out[u] = border == 0 ? std::make_pair(Eigen::Vector3d(x.col(0)), Eigen::Vector3d(x.col(1)))
                         : std::make_pair(Eigen::Vector3d(x.col(3)), Eigen::Vector3d(x.col(2)));
  });
  return out;
}

Cifs side_system(const TensorSurface& s) { return Cifs{"side", tensor_product(s.u, s.v), s.control_points, false}; }

// J's six transformations (two along u, three across: to A's nature, to the junction, to B's), and at levels
// 1-6 its v = 0 border pieces (first to A's nature, then A's first symbol) against A's at v = 1 (A's last
// symbol) and its v = 1 pieces against B's at v = 0: the same 2^L words, every corner within 1e-12. `apart`
// (when given) gets per level the largest distance between the first corners of J's two borders.
void expect_borders_on_the_sides(Cifs j, Cifs a, Cifs b, std::vector<double>* apart = nullptr) {
  for (Cifs* c : {&j, &a, &b}) complete_primitives(c->automaton);
  ASSERT_EQ(j.automaton.transitions[size_t(j.automaton.initial)].size(), 6u);
  const int wj = j.automaton.alphabet_size / 2, wa = a.automaton.alphabet_size / 2, wb = b.automaton.alphabet_size / 2;
  ASSERT_EQ(wj, 3);
  for (int level = 1; level <= 6; ++level) {
    const auto j0 = border_pieces(j, level, wj, 0, 0, 0), a1 = border_pieces(a, level, wa, wa - 1, wa - 1, 1);
    const auto j1 = border_pieces(j, level, wj, 2, wb - 1, 1), b0 = border_pieces(b, level, wb, 0, 0, 0);
    ASSERT_EQ(j0.size(), size_t(1) << level);
    ASSERT_EQ(a1.size(), j0.size());
    ASSERT_EQ(j1.size(), j0.size());
    ASSERT_EQ(b0.size(), j0.size());
    double worst = 0, far = 0;
    for (const auto& [word, corners] : j0) {
      worst = std::max({worst, (corners.first - a1.at(word).first).norm(), (corners.second - a1.at(word).second).norm()});
      worst = std::max({worst, (j1.at(word).first - b0.at(word).first).norm(), (j1.at(word).second - b0.at(word).second).norm()});
      far = std::max(far, (corners.first - j1.at(word).first).norm());
    }
    EXPECT_LT(worst, 1e-12) << "level " << level;
    if (apart) apart->push_back(far);
  }
}

TEST(Junction, BorderPiecesCoincideWithTheSidesAtEveryLevel) {
  const JunctionSides s = junction_sides();
  expect_borders_on_the_sides(junction(s.a, s.b, JunctionOptions{}), side_system(s.a), side_system(s.b));
}

// The welded mesh of a surface: vertices, edges, faces and boundary edges.
struct MeshCounts {
  long vertices = 0, edges = 0, faces = 0, boundary = 0;
};

MeshCounts counts(const TriMesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (const auto& t : m.triangles)
    for (int e = 0; e < 3; ++e) ++edges[{std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])}];
  MeshCounts c;
  c.vertices = long(m.positions_mm.size());
  c.faces = long(m.triangles.size());
  c.edges = long(edges.size());
  for (const auto& [edge, n] : edges) c.boundary += n == 1;
  return c;
}

// At levels 1-5: the assembly `all` (junction with sides) is A, J and B each at level L, and welded the
// three are one disc: no seam between them (a seam would leave boundary edges inside and raise the Euler
// characteristic above 1) and no overlap; J alone is one too. The outline is the four borders, 2^L edges
// along u each, and the pieces across v on the two sides.
void expect_one_disc(const Cifs& all, const Cifs& a, const Cifs& b, const Cifs& j) {
  for (int level = 1; level <= 5; ++level) {
    EXPECT_EQ(count_pieces(all.automaton, level),
              count_pieces(a.automaton, level) + count_pieces(j.automaton, level) + count_pieces(b.automaton, level));
    const MeshCounts c = counts(tessellate_surface(all, level));
    EXPECT_EQ(c.vertices - c.edges + c.faces, 1) << "level " << level;
    const MeshCounts cj = counts(tessellate_surface(j, level));
    EXPECT_EQ(cj.vertices - cj.edges + cj.faces, 1) << "level " << level;
    EXPECT_EQ(c.boundary, 2 * (1L << level) + 2 * long(count_pieces(all.automaton, level) >> level)) << "level " << level;
  }
}

TEST(Junction, JunctionAndSidesAreOneDiscAndTheMiddleShrinksToTheMidpoint) {
  const JunctionSides s = junction_sides();
  JunctionOptions options;
  options.sides = true;
  Cifs all = junction(s.a, s.b, options);
  Cifs a = side_system(s.a), b = side_system(s.b), j = junction(s.a, s.b, JunctionOptions{});
  expect_one_disc(all, a, b, j);
  // The junction's middle (u, v) = (any, J^w) is the midpoint of A's end and B's start, row by row:
  // at u = 0 it is the midpoint of the two surfaces' corner points there.
  const Eigen::VectorXd m = limit_point(j.automaton, j.automaton.initial, 1);  // u symbol 0, v symbol 1 (J)
  const Eigen::Vector3d middle = j.control_points * m;
  Cifs ca = a, cb = b;
  complete_primitives(ca.automaton);
  complete_primitives(cb.automaton);
  const Eigen::Vector3d a_corner = ca.control_points * ca.automaton.states[size_t(ca.automaton.initial)].vertices.col(3);
  const Eigen::Vector3d b_corner = cb.control_points * cb.automaton.states[size_t(cb.automaton.initial)].vertices.col(0);
  EXPECT_LT((middle - 0.5 * (a_corner + b_corner)).norm(), 1e-9);
}

// A bi-quadratic NURBS patch A and a Takagi x Takagi patch B whose v = 0 border has A's v = 1 border
// polygon as its control polygon: the two borders share one polygon and differ in nature along u (A's
// runs near the polygon's middle, B's from its first point to its second, lifted by its third).
JunctionSides shared_polygon_sides() {
  JunctionSides s;
  s.a = junction_sides().a;
  s.a.control_points(2, 1 * 3 + 2) += 4;  // A's border polygon bends (a straight one would flatten B's Takagi frame)
  s.b.u = library_system("takagi_curve").automaton;
  s.b.v = s.b.u;
  s.b.control_points.resize(3, 9);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d border = 0.5 * (s.a.control_points.col(i * 3 + 1) + s.a.control_points.col(i * 3 + 2));
    s.b.control_points.col(i * 3) = border;
    s.b.control_points.col(i * 3 + 1) = border + Eigen::Vector3d(0, 10, 0);
    s.b.control_points.col(i * 3 + 2) = border + Eigen::Vector3d(0, 0, 3);
  }
  return s;
}

// The point of `c` reached by the finite word, then the corner `corner` of the piece it addresses.
Eigen::Vector3d word_corner(const Cifs& c, const std::vector<int>& word, int corner) {
  int state = c.automaton.initial;
  Eigen::MatrixXd m = Eigen::MatrixXd::Identity(c.control_points.cols(), c.control_points.cols());
  for (int symbol : word) {
    const Transition* t = find_transition(c.automaton, state, symbol);
    EXPECT_NE(t, nullptr);
    if (!t) return Eigen::Vector3d::Zero();
    m = Eigen::MatrixXd(m * t->matrix);
    state = t->target;
  }
  return c.control_points * m * c.automaton.states[size_t(state)].vertices.col(corner);
}

TEST(Junction, BordersOfTwoNaturesAlongUMeetOnAStraightSeam) {
  const JunctionSides s = shared_polygon_sides();
  Cifs j = junction(s.a, s.b, JunctionOptions{});
  Cifs a = side_system(s.a), b = side_system(s.b);
  complete_primitives(a.automaton);
  complete_primitives(b.automaton);
  // A's u automaton is a non-uniform quadratic NURBS, B's a Takagi curve: J adds F_A and F_B per point of u.
  EXPECT_EQ(j.control_points.cols(), 3 * (3 + 2 + 3));
  std::vector<double> apart;
  expect_borders_on_the_sides(j, a, b, &apart);
  ASSERT_EQ(apart.size(), 6u);
  for (size_t level = 0; level < apart.size(); ++level)
    EXPECT_GT(apart[level], 1.0) << "the two borders are different curves; level " << level + 1;
  // The middle (v symbol J forever) is the straight segment from X, the middle of the borders' start
  // points, to Y, of their end points, with u as its parameter on both natures' sides: at u = 0, 1/4,
  // 1/2 and 1 (u symbols 0^w, 010^w, 10^w, 1^w), the corners of the deep middle pieces.
  const Eigen::MatrixXd &av = a.automaton.states[size_t(a.automaton.initial)].vertices,
                        &bv = b.automaton.states[size_t(b.automaton.initial)].vertices;
  const Eigen::Vector3d x = 0.5 * (a.control_points * av.col(3) + b.control_points * bv.col(0));
  const Eigen::Vector3d y = 0.5 * (a.control_points * av.col(2) + b.control_points * bv.col(1));
  const std::vector<std::pair<std::vector<int>, double>> words = {{{}, 0.0}, {{0, 1}, 0.25}, {{1}, 0.5}, {{1, 1, 1}, 1.0}};
  for (const auto& [prefix, u] : words) {
    std::vector<int> word;
    for (size_t i = 0; i < 40; ++i) word.push_back(3 * (i < prefix.size() ? prefix[i] : (u == 1.0 ? 1 : 0)) + 1);
    for (int corner : {0, 3}) {
      const Eigen::Vector3d p = word_corner(j, word, corner);
      EXPECT_LT((p - (x + u * (y - x))).norm(), 1e-9) << "u " << u << " corner " << corner;
    }
  }
}

TEST(Junction, TwoNaturesAlongUWeldIntoOneDisc) {
  // B moved 4 mm on and 2 mm up: with one shared polygon (three points, so one plane) the two borders
  // cross in its plane and J folds flat onto itself, where welding would join unrelated vertices.
  JunctionSides s = shared_polygon_sides();
  s.b.control_points.colwise() += Eigen::Vector3d(0, 4, 2);
  JunctionOptions options;
  options.sides = true;
  options.ratio = 0.25;
  Cifs all = junction(s.a, s.b, options);
  Cifs a = side_system(s.a), b = side_system(s.b);
  options.sides = false;
  expect_one_disc(all, a, b, junction(s.a, s.b, options));
}

// A curve automaton on three points that splits its quadratic Bezier arc at t = 0.3 (de Casteljau):
// a straight segment drawn with it has unequal pieces.
Automaton bezier_split(double t) {
  Eigen::MatrixXd left = Eigen::MatrixXd::Zero(3, 3), right = Eigen::MatrixXd::Zero(3, 3);
  left.col(0) << 1, 0, 0;
  left.col(1) << 1 - t, t, 0;
  left.col(2) << (1 - t) * (1 - t), 2 * t * (1 - t), t * t;
  right.col(0) = left.col(2);
  right.col(1) << 0, 1 - t, t;
  right.col(2) << 0, 0, 1;
  Automaton a;
  State st;
  st.name = "bezier";
  st.control_points = 3;
  a.states.push_back(st);
  a.transitions.push_back({Transition{0, 0, left}, Transition{1, 0, right}});
  return a;
}

TEST(Junction, RefusesUAutomataThatCannotMeetAndBadOptions) {
  JunctionSides s = shared_polygon_sides();
  TensorSurface uneven = s.b;
  uneven.u = bezier_split(0.3);
  try {
    junction(s.a, uneven, JunctionOptions{});
    FAIL() << "a u automaton without equal pieces on a segment was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("linear precision"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("side B"), std::string::npos) << e.what();
  }
  // Halves of a Bezier arc do have linear precision: accepted.
  TensorSurface even = s.b;
  even.u = bezier_split(0.5);
  EXPECT_NO_THROW(junction(s.a, even, JunctionOptions{}));
  TensorSurface cubic = s.b;  // a u automaton on four points: the borders cannot share A's polygon
  cubic.u = nurbs_automaton(3, {0, 1, 2, 3, 4, 5}).automaton;
  cubic.control_points.conservativeResize(3, 12);
  try {
    junction(s.a, cubic, JunctionOptions{});
    FAIL() << "a u automaton on four points was joined to one on three";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("control points"), std::string::npos) << e.what();
  }
  // Three points that split into two-point pieces (the quadratic Bezier's halves drawn as their chords,
  // linear precision with the parameter 0, 1/2, 1) meet A's three-point pieces in sizes that differ.
  TensorSurface chords = s.b;
  {
    Automaton a;
    State three, two;
    three.name = "three";
    three.control_points = 3;
    two.name = "two";
    two.control_points = 2;
    a.states = {three, two};
    Eigen::MatrixXd left(3, 2), right(3, 2), half_left(2, 2), half_right(2, 2);
    left << 1, 0.25, 0, 0.5, 0, 0.25;
    right << 0.25, 0, 0.5, 0, 0.25, 1;
    half_left << 1, 0.5, 0, 0.5;
    half_right << 0.5, 0, 0.5, 1;
    a.transitions = {{Transition{0, 1, left}, Transition{1, 1, right}}, {Transition{0, 1, half_left}, Transition{1, 1, half_right}}};
    chords.u = a;
  }
  try {
    junction(s.a, chords, JunctionOptions{});
    FAIL() << "u automata whose pieces differ in size were joined";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("differ in size"), std::string::npos) << e.what();
  }
  JunctionOptions wide;
  wide.ratio = 0.5;
  EXPECT_THROW(junction(s.a, s.b, wide), InvalidInput);
  const JunctionSides same_u = junction_sides();
  TensorSurface touching = same_u.b;  // B starting on A's end (the uniform quadratic piece ends mid-way on its last leg)
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d shift = 0.5 * (same_u.a.control_points.col(i * 3 + 1) + same_u.a.control_points.col(i * 3 + 2)) -
                                  same_u.b.control_points.col(i * 3);
    for (int l = 0; l < 3; ++l) touching.control_points.col(i * 3 + l) += shift;
  }
  EXPECT_THROW(junction(same_u.a, touching, JunctionOptions{}), InvalidInput);
}

TEST(Junction, ReadFromJsonWithTheSidesAsSystems) {
  const nlohmann::json side_a = {{"nurbs_surface", {{"u", {{"degree", 2}, {"knots", {0, 1, 3, 4}}}}, {"v", {{"degree", 2}, {"knots", {0, 1, 2, 3}}}}}},
                                 {"control_points_mm", {{{0, 0, 0}, {0, 5, 1}, {0, 10, 0}}, {{6, 0, 1}, {6, 5, 0}, {6, 10, 1}}, {{12, 0, 0}, {12, 5, 1}, {12, 10, 0}}}}};
  const nlohmann::json side_b = {{"product", {{{"nurbs_curve", {{"degree", 2}, {"knots", {0, 1, 3, 4}}}}, {"control_points_mm", {{0, 0, 0}, {6, 0, 0}, {12, 0, 0}}}}, "takagi_curve"}},
                                 {"translate_mm", {0, 14, 0}}};
  nlohmann::json system = {{"junction", {{"a", side_a}, {"b", side_b}, {"sides", true}}}};
  Cifs c = parse_system(system, "r.json", "system");
  EXPECT_EQ(c.control_points.cols(), 3 * 6);
  // The assembly's first symbols: A's 2 x 2, J's 2 x 3, B's 2 x 2.
  EXPECT_EQ(c.automaton.transitions[size_t(c.automaton.initial)].size(), 14u);
  system["junction"]["ratio"] = 0.7;
  try {
    parse_system(system, "r.json", "system");
    FAIL() << "a ratio of 0.7 was accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("ratio"), std::string::npos) << e.what();
  }
  // B of another u automaton (uniform knots): J gains the two free points per point of u.
  system["junction"]["ratio"] = 0.25;
  system["junction"]["b"]["product"][0]["nurbs_curve"]["knots"] = {0, 1, 2, 3};
  EXPECT_EQ(parse_system(system, "r.json", "system").control_points.cols(), 3 * 8);
  system["junction"]["b"]["product"][0] = "koch_curve";
  try {
    parse_system(system, "r.json", "system");
    FAIL() << "sides whose u automata cannot meet were accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("symbols"), std::string::npos) << e.what();  // Koch has four pieces
  }
}

}  // namespace
}  // namespace cifs
}  // namespace lacuna

namespace lacuna {
namespace cifs {
namespace {

// A bi-quadratic dome over [0, 20] x [0, 16] between z = 10 and 14, non-uniform along u.
Cifs dome() {
  Cifs c{"dome", tensor_product(nurbs_automaton(2, {0, 1, 3, 4}).automaton, nurbs_automaton(2, {0, 1, 2, 3}).automaton),
         Eigen::MatrixXd(3, 9), false};
  for (int i = 0; i < 3; ++i)
    for (int l = 0; l < 3; ++l) c.control_points.col(i * 3 + l) << 10.0 * i, 8.0 * l, (i == 1 && l == 1) ? 16 : 10 + i;
  complete_primitives(c.automaton);
  return c;
}

TEST(Support, BranchTopsAreTheSurfacePiecesAtEveryLevel) {
  const Cifs surface = dome();
  SupportOptions options;
  options.base_center_mm = Vec3d{10, 8, 0};
  const Cifs tree = support_tree(surface, options);
  const int trunk_symbol = surface.automaton.alphabet_size;
  for (int level = 0; level <= 5; ++level) {
    // Level L: a trunk for every piece of the levels before, a branch for every piece of this one.
    uint64_t trunks = 0;
    for (int l = 0; l < level; ++l) trunks += count_pieces(surface.automaton, l);
    ASSERT_EQ(count_pieces(tree.automaton, level), trunks + count_pieces(surface.automaton, level));
    std::map<std::vector<int>, Eigen::Matrix3Xd> pieces;
    for_each_piece(surface, level, [&](const Piece& p) { pieces[*p.word] = *p.vertices; });
    size_t branches = 0;
    double worst = 0;
    for_each_piece(tree, level, [&](const Piece& p) {
      if (std::find(p.word->begin(), p.word->end(), trunk_symbol) != p.word->end()) return;
      ++branches;
      const Eigen::Matrix3Xd& top = pieces.at(*p.word);
      for (int c = 0; c < 4; ++c) worst = std::max(worst, (p.vertices->col(4 + c) - top.col(c)).norm());
    });
    EXPECT_EQ(branches, pieces.size());
    EXPECT_LT(worst, 1e-12) << "level " << level;
  }
  // The root stands on the plate: level 0's base corners at z = 0 about the given centre.
  for_each_piece(tree, 0, [&](const Piece& p) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(p.vertices->col(c).z(), 0.0, 1e-12);
      centre += p.vertices->col(c) / 4;
    }
    EXPECT_LT((centre - Eigen::Vector3d(10, 8, 0)).norm(), 1e-12);
  });
}

TEST(Support, ChildrenStartOnTheirParentsFork) {
  // Every level-1 branch's base is its parent's trunk top: the fork quad, halfway up and half the base.
  const Cifs surface = dome();
  SupportOptions options;
  options.base_center_mm = Vec3d{10, 8, 0};
  options.base_size_mm = 4;
  const Cifs tree = support_tree(surface, options);
  Eigen::Matrix3Xd trunk, root;
  for_each_piece(tree, 0, [&](const Piece& p) { root = *p.vertices; });
  std::vector<Eigen::Matrix3Xd> children;
  for_each_piece(tree, 1, [&](const Piece& p) {
    if (p.state == int(tree.automaton.states.size()) - 1) trunk = *p.vertices;
    else children.push_back(*p.vertices);
  });
  ASSERT_EQ(children.size(), 4u);
  const Eigen::Vector3d base_centre = root.leftCols(4).rowwise().mean(), top_centre = root.rightCols(4).rowwise().mean();
  const Eigen::Vector3d fork = 0.5 * (base_centre + top_centre);
  for (int c = 0; c < 4; ++c) {
    EXPECT_LT((trunk.col(c) - root.col(c)).norm(), 1e-12);
    const Eigen::Vector3d corner = fork + 0.5 * (root.col(c) - base_centre);
    EXPECT_LT((trunk.col(4 + c) - corner).norm(), 1e-12);
    for (const auto& child : children) EXPECT_LT((child.col(c) - corner).norm(), 1e-12);
  }
  // The root base is 4 mm across its widest diagonal.
  double widest = 0;
  for (int c = 0; c < 4; ++c) widest = std::max(widest, (root.col(c) - base_centre).norm());
  EXPECT_NEAR(2 * widest, 4.0, 1e-12);
}

TEST(Support, RefusesABaseAboveTheSurfaceAndCurves) {
  SupportOptions options;
  options.base_center_mm = Vec3d{10, 8, 11.5};  // the dome's lowest point is its corner at z = 11.17
  EXPECT_THROW(support_tree(dome(), options), InvalidInput);
  options.base_center_mm.z = 0;
  EXPECT_THROW(support_tree(library_system("takagi_curve"), options), InvalidInput);
  options.fork = 1;
  EXPECT_THROW(support_tree(dome(), options), InvalidInput);
}

}  // namespace
}  // namespace cifs
}  // namespace lacuna
