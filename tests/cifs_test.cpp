// The CIFS engine, NURBS automata and shipped systems against known values.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "cifs/automaton.h"
#include "cifs/library.h"
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
