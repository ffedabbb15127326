// Fractal Voronoi partitions: rule counts from the definition, the worked 2D example of the spec, the rule
// matrix's column sums and Perron vector, level sizes, exact cell measures against closed forms and an
// independent nearest-generator sampling, their convergence to the limit measures, determinism.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numeric>
#include <vector>

#include "errors.h"
#include "pipeline/build_inputs.h"
#include "recipe/recipe.h"
#include "voronoi/rules.h"
#include "voronoi/walls.h"

namespace lacuna {
namespace {

using voronoi::Level;
using voronoi::Rules;

const std::vector<std::vector<double>> kExample = {{0.86, 0.3}, {0.3, 0.65}, {0.73, 0.85}};

double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

double max_error(const std::vector<double>& a, const std::vector<double>& b) {
  double e = 0;
  for (size_t i = 0; i < a.size(); ++i) e = std::max(e, std::fabs(a[i] - b[i]));
  return e;
}

voronoi::RulesOptions scaled() {
  voronoi::RulesOptions options;
  options.children = voronoi::RulesOptions::Children::kScaled;
  return options;
}

// Nearest generator (ties to the lower index) of every sample point on a regular grid: an estimate of the
// colour measures independent of the clipping.
std::vector<double> sampled_measures(const Level& level, int samples_per_axis) {
  std::vector<double> measures(size_t(level.colour_count), 0.0);
  const int n = level.dimension;
  const long total = long(std::pow(samples_per_axis, n));
  std::vector<double> x(static_cast<size_t>(n));
  for (long s = 0; s < total; ++s) {
    long t = s;
    for (int j = 0; j < n; ++j) {
      x[size_t(j)] = (double(t % samples_per_axis) + 0.5) / samples_per_axis;
      t /= samples_per_axis;
    }
    size_t best = 0;
    double best_d2 = 1e300;
    for (size_t i = 0; i < level.points.size(); ++i) {
      const double d2 = voronoi::torus_distance_squared(level.points[i], x);
      if (d2 < best_d2) {
        best_d2 = d2;
        best = i;
      }
    }
    measures[size_t(level.colours[best])] += 1.0 / double(total);
  }
  return measures;
}

TEST(VoronoiRules, ChildCountIsDnTimesM) {
  for (int n : {2, 3})
    for (int d : {2, 3})
      for (int m : {1, 2, 5, 9}) {
        for (bool use_scaled : {false, true}) {
          const Rules rules = voronoi::make_rules(n, d, voronoi::random_points(n, m, uint64_t(100 * n + 10 * d + m)),
                                                  use_scaled ? scaled() : voronoi::RulesOptions{});
          size_t total = 0;
          for (const auto& rule : rules.rules) total += rule.size();
          EXPECT_EQ(total, size_t(std::pow(d, n)) * size_t(m)) << "n " << n << " d " << d << " m " << m;
          ASSERT_EQ(rules.rules.size(), size_t(m));
          // Every rule holds its own point's child at a = 0, offset 0.
          for (int r = 0; r < m; ++r) {
            bool found = false;
            for (const auto& child : rules.rules[size_t(r)])
              found = found || (child.follows == r && child.offset == std::vector<double>(size_t(n), 0.0));
            // With the scaled children p(r) + 0 lands at p(r)/d instead.
            if (!use_scaled) {
              EXPECT_TRUE(found) << "rule " << r;
            }
          }
        }
      }
}

TEST(VoronoiRules, SinglePoint) {
  for (int n : {2, 3}) {
    const Rules rules = voronoi::make_rules(n, 3, {std::vector<double>(size_t(n), 0.25)});
    ASSERT_EQ(rules.rules.size(), 1u);
    ASSERT_EQ(rules.rules[0].size(), size_t(std::pow(3, n)));
    for (const auto& child : rules.rules[0]) EXPECT_EQ(child.follows, 0);
    EXPECT_EQ(rules.matrix(0, 0), std::pow(3, n));
    ASSERT_EQ(rules.limit_measures.size(), 1u);
    EXPECT_DOUBLE_EQ(rules.limit_measures[0], 1.0);
    // Offsets are the lattice a/3 moved to the nearest copy: components in {-1/3, 0, 1/3}.
    for (const auto& child : rules.rules[0])
      for (double u : child.offset) EXPECT_LT(std::fabs(u), 0.34);
    const Level zero = voronoi::generate_level(rules, 0);
    const std::vector<double> measures = n == 2 ? voronoi::cell_measures_2d(zero) : voronoi::cell_measures_3d(zero);
    ASSERT_EQ(measures.size(), 1u);
    EXPECT_NEAR(measures[0], 1.0, 1e-15);
    EXPECT_TRUE(rules.graph_connected_condition);  // no pairs at either level
  }
}

TEST(VoronoiRules, SpecExample2D) {
  const Rules rules = voronoi::make_rules(2, 2, kExample);
  // Point 1 of the spec (index 0): children following rules 1, 2, 2, 3 (1-based).
  std::vector<int> follows;
  for (const auto& child : rules.rules[0]) follows.push_back(child.follows);
  EXPECT_EQ(follows, (std::vector<int>{0, 1, 1, 2}));  // loop order: starting point i, then a
  // The scaled children q = (p(i) + a)/2 give the same multiset for point 1: (0.93, 0.15) from p(0);
  // (0.15, 0.325), (0.65, 0.325) from p(1); (0.865, 0.425) from p(2).
  const Rules scaled_rules = voronoi::make_rules(2, 2, kExample, scaled());
  follows.clear();
  for (const auto& child : scaled_rules.rules[0]) follows.push_back(child.follows);
  EXPECT_EQ(follows, (std::vector<int>{0, 1, 1, 2}));
  // Worked by hand: q = p(i) + a/2 and its nearest starting point.
  Eigen::MatrixXd expected(3, 3);
  expected << 1, 2, 1, 2, 1, 2, 1, 1, 1;
  EXPECT_EQ(rules.matrix, expected);
  // Child of rule 0 from p(1) + (1,1)/2 = (0.8, 0.15): u = (0.8 - 0.86, 0.15 - 0.3).
  const auto& child = rules.rules[0][2];
  EXPECT_NEAR(child.offset[0], -0.06, 1e-15);
  EXPECT_NEAR(child.offset[1], -0.15, 1e-15);
  // Child of rule 1 from p(0) + (1,0)/2 = (0.36, 0.3): u = (0.06, -0.35).
  EXPECT_NEAR(rules.rules[1][0].offset[0], 0.06, 1e-15);
  EXPECT_NEAR(rules.rules[1][0].offset[1], -0.35, 1e-15);
  // The Perron vector of this M: M a = 4 a with sum 1 gives a = (7, 8, 5) / 20.
  EXPECT_NEAR(rules.limit_measures[0], 7.0 / 20, 1e-14);
  EXPECT_NEAR(rules.limit_measures[1], 8.0 / 20, 1e-14);
  EXPECT_NEAR(rules.limit_measures[2], 5.0 / 20, 1e-14);
}

TEST(VoronoiRules, WrappedOffsetAndTies) {
  // Dyadic coordinates make every distance exact. q = p(0) + (1, 0)/2 = (0.375, 0.125) is at squared distance
  // 1/4 from both p(0) (across the wrap in x) and p(1) (in y): the tie goes to colour 0, with u_x = +1/2.
  const Rules rules = voronoi::make_rules(2, 2, {{0.875, 0.125}, {0.375, 0.625}});
  for (const auto& rule : rules.rules)
    for (const auto& child : rule)
      for (double u : child.offset) {
        EXPECT_GT(u, -0.5);
        EXPECT_LE(u, 0.5);
      }
  ASSERT_EQ(rules.rules[0].size(), 6u);
  EXPECT_EQ(rules.rules[0][1].follows, 0);
  EXPECT_EQ(rules.rules[0][1].offset, (std::vector<double>{0.5, 0.0}));
  // p(0) + (0, 1)/2 = (0.875, 0.625) ties p(0) (in y) and p(1) (across the wrap in x): colour 0 again.
  EXPECT_EQ(rules.rules[0][2].follows, 0);
  EXPECT_EQ(rules.rules[0][2].offset, (std::vector<double>{0.0, 0.5}));
  // Rule 1 keeps only the two children that land exactly on p(1): p(0) + (1, 1)/2 and p(1) itself.
  ASSERT_EQ(rules.rules[1].size(), 2u);
  EXPECT_EQ(rules.rules[1][0].follows, 0);
  EXPECT_EQ(rules.rules[1][1].follows, 1);
}

TEST(VoronoiRules, ColumnSumsAndPerronVector) {
  for (int n : {2, 3})
    for (int d : {2, 3})
      for (int m : {2, 4, 7}) {
        for (bool use_scaled : {false, true}) {
          const Rules rules = voronoi::make_rules(n, d, voronoi::random_points(n, m, uint64_t(7 * m + d + 31 * n)),
                                                  use_scaled ? scaled() : voronoi::RulesOptions{});
          const double dn = std::pow(d, n);
          // Column i counts every child of p(i): d^n. Row sums are the rule sizes.
          for (int i = 0; i < m; ++i) EXPECT_EQ(rules.matrix.col(i).sum(), dn);
          for (int r = 0; r < m; ++r) EXPECT_EQ(rules.matrix.row(r).sum(), double(rules.rules[size_t(r)].size()));
          const Eigen::Map<const Eigen::VectorXd> a(rules.limit_measures.data(), m);
          EXPECT_NEAR(a.sum(), 1.0, 1e-12);
          EXPECT_GE(a.minCoeff(), 0.0);
          EXPECT_LE((rules.matrix * a - dn * a).cwiseAbs().maxCoeff(), 1e-12);
        }
      }
}

TEST(VoronoiRules, RejectsBadInput) {
  EXPECT_THROW(voronoi::make_rules(4, 2, {{0.1, 0.1, 0.1, 0.1}}), InvalidInput);
  EXPECT_THROW(voronoi::make_rules(2, 1, {{0.1, 0.1}}), InvalidInput);
  EXPECT_THROW(voronoi::make_rules(2, 2, {}), InvalidInput);
  EXPECT_THROW(voronoi::make_rules(2, 2, {{0.1, 1.0}}), InvalidInput);
  EXPECT_THROW(voronoi::make_rules(2, 2, {{0.1, -0.1}}), InvalidInput);
  EXPECT_THROW(voronoi::make_rules(2, 2, {{0.1, NAN}}), InvalidInput);
  EXPECT_THROW(voronoi::make_rules(2, 2, {{0.1, 0.2, 0.3}}), InvalidInput);
  EXPECT_THROW(voronoi::make_rules(2, 2, {{0.1, 0.2}, {0.5, 0.5}, {0.1, 0.2}}), InvalidInput);
  EXPECT_THROW(voronoi::make_rules(3, 100, voronoi::random_points(3, 2, 1)), ResourceLimit);
  try {
    voronoi::make_rules(2, 2, {{0.1, 0.2}, {0.5, 0.5}, {0.1, 0.2}});
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("starting point 2 coincides with starting point 0"), std::string::npos);
  }
  const Rules rules = voronoi::make_rules(3, 3, voronoi::random_points(3, 10, 1));
  EXPECT_THROW(voronoi::generate_level(rules, -1), InvalidInput);
  EXPECT_THROW(voronoi::generate_level(rules, 5), ResourceLimit);  // 27^5 * 10 > 2e7
}

TEST(VoronoiLevel, CountsAndColours) {
  const Rules rules = voronoi::make_rules(2, 2, kExample);
  for (int k = 0; k <= 4; ++k) {
    const Level level = voronoi::generate_level(rules, k);
    EXPECT_EQ(level.points.size(), size_t(std::pow(4, k)) * 3);
    ASSERT_EQ(level.colours.size(), level.points.size());
    for (const auto& p : level.points)
      for (double x : p) EXPECT_TRUE(x >= 0 && x < 1);
    // Colour s has as many points as (M^k 1)_s.
    Eigen::VectorXd counts = Eigen::VectorXd::Ones(3);
    for (int i = 0; i < k; ++i) counts = rules.matrix * counts;
    for (int s = 0; s < 3; ++s)
      EXPECT_EQ(std::count(level.colours.begin(), level.colours.end(), s), long(counts(s))) << "k " << k;
  }
  // Level 1 is every p(i) + a/d.
  const Level one = voronoi::generate_level(rules, 1);
  for (int i = 0; i < 3; ++i)
    for (int a0 = 0; a0 < 2; ++a0)
      for (int a1 = 0; a1 < 2; ++a1) {
        const std::vector<double> q{std::fmod(kExample[size_t(i)][0] + a0 / 2.0, 1.0),
                                    std::fmod(kExample[size_t(i)][1] + a1 / 2.0, 1.0)};
        double best = 1;
        for (const auto& p : one.points) best = std::min(best, voronoi::torus_distance_squared(p, q));
        EXPECT_LT(best, 1e-28);
      }
  const Rules rules3 = voronoi::make_rules(3, 2, voronoi::random_points(3, 3, 5));
  EXPECT_EQ(voronoi::generate_level(rules3, 2).points.size(), 64u * 3);
}

TEST(VoronoiCells, ClosedForms) {
  Level two;
  two.dimension = 2;
  two.colour_count = 2;
  two.points = {{0.25, 0.5}, {0.75, 0.5}};
  two.colours = {0, 1};
  std::vector<double> m2 = voronoi::cell_measures_2d(two);
  EXPECT_NEAR(m2[0], 0.5, 1e-15);
  EXPECT_NEAR(m2[1], 0.5, 1e-15);
  // A 3 x 3 lattice coloured by rows: each colour holds a third.
  Level lattice;
  lattice.dimension = 2;
  lattice.colour_count = 3;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      lattice.points.push_back({(i + 0.1) / 3, (j + 0.7) / 3});
      lattice.colours.push_back(j);
    }
  m2 = voronoi::cell_measures_2d(lattice);
  for (double v : m2) EXPECT_NEAR(v, 1.0 / 3, 1e-15);
  EXPECT_EQ(voronoi::colour_graph(lattice), (std::vector<std::pair<int, int>>{{0, 1}, {0, 2}, {1, 2}}));
  // Coincident generators (here 1e-17 apart, as rounding leaves them) share their cell equally.
  Level dup = two;
  dup.colour_count = 3;
  dup.points.push_back({0.25 + 1e-17, 0.5});
  dup.colours.push_back(2);
  m2 = voronoi::cell_measures_2d(dup);
  EXPECT_NEAR(m2[0], 0.25, 1e-15);
  EXPECT_NEAR(m2[1], 0.5, 1e-15);
  EXPECT_NEAR(m2[2], 0.25, 1e-15);
  EXPECT_EQ(voronoi::colour_graph(dup), (std::vector<std::pair<int, int>>{{0, 1}, {0, 2}, {1, 2}}));
  // 3D: two points on a line split the torus in halves; a 2 x 2 x 2 lattice in eighths.
  Level three;
  three.dimension = 3;
  three.colour_count = 2;
  three.points = {{0.1, 0.5, 0.5}, {0.6, 0.5, 0.5}};
  three.colours = {0, 1};
  std::vector<double> m3 = voronoi::cell_measures_3d(three);
  EXPECT_NEAR(m3[0], 0.5, 1e-14);
  EXPECT_NEAR(m3[1], 0.5, 1e-14);
  Level cube;
  cube.dimension = 3;
  cube.colour_count = 8;
  for (int i = 0; i < 8; ++i) {
    cube.points.push_back({0.2 + 0.5 * (i & 1), 0.3 + 0.5 * ((i >> 1) & 1), 0.05 + 0.5 * (i >> 2)});
    cube.colours.push_back(i);
  }
  m3 = voronoi::cell_measures_3d(cube);
  for (double v : m3) EXPECT_NEAR(v, 0.125, 1e-14);
  EXPECT_THROW(voronoi::cell_measures_3d(two), InvalidInput);
}

TEST(VoronoiCells, MatchSampling) {
  // Exact cell measures against nearest-generator sampling of the same level (independent computation).
  const Rules rules = voronoi::make_rules(2, 2, kExample);
  const Level level = voronoi::generate_level(rules, 2);
  const std::vector<double> exact = voronoi::cell_measures_2d(level);
  EXPECT_NEAR(sum(exact), 1.0, 1e-12);
  EXPECT_LT(max_error(exact, sampled_measures(level, 400)), 3e-3);
  const Rules rules3 = voronoi::make_rules(3, 2, voronoi::random_points(3, 4, 11));
  const Level level3 = voronoi::generate_level(rules3, 1);
  const std::vector<double> exact3 = voronoi::cell_measures_3d(level3);
  EXPECT_NEAR(sum(exact3), 1.0, 1e-12);
  EXPECT_LT(max_error(exact3, sampled_measures(level3, 60)), 5e-3);
}

TEST(VoronoiCells, ConvergeToLimitMeasures2D) {
  // Only with the scaled children: see SpecShiftedChildrenCoincide.
  for (const auto& start : {kExample, voronoi::random_points(2, 5, 2024)}) {
    const Rules rules = voronoi::make_rules(2, 2, start, scaled());
    std::vector<double> error;
    for (int k = 0; k <= 6; ++k) {
      const std::vector<double> measures = voronoi::cell_measures_2d(voronoi::generate_level(rules, k));
      EXPECT_NEAR(sum(measures), 1.0, 1e-9);
      error.push_back(max_error(measures, rules.limit_measures));
    }
    EXPECT_LT(error[4], error[1]);
    EXPECT_LT(error[4], error[2]);
    EXPECT_LT(error[6], 1e-3);
  }
}

TEST(VoronoiCells, ConvergeToLimitMeasures3D) {
  const Rules rules = voronoi::make_rules(3, 2, voronoi::random_points(3, 3, 99), scaled());
  std::vector<double> error;
  for (int k = 0; k <= 3; ++k) {
    const std::vector<double> measures = voronoi::cell_measures_3d(voronoi::generate_level(rules, k));
    EXPECT_NEAR(sum(measures), 1.0, 1e-9);
    error.push_back(max_error(measures, rules.limit_measures));
  }
  EXPECT_LT(error[3], error[1]);
}

// The spec's step 1 as written (q = p(i) + a/d) puts level-2 points at the same site by different paths, some
// with different colours, and the measures settle away from the Perron vector; the scaled children do not.
TEST(VoronoiCells, SpecShiftedChildrenCoincide) {
  auto coincident_pairs = [](const Level& level) {
    int pairs = 0;
    for (size_t i = 0; i < level.points.size(); ++i)
      for (size_t j = i + 1; j < level.points.size(); ++j)
        pairs += voronoi::torus_distance_squared(level.points[i], level.points[j]) < 1e-24;
    return pairs;
  };
  const Rules shifted = voronoi::make_rules(2, 2, kExample);
  EXPECT_EQ(coincident_pairs(voronoi::generate_level(shifted, 1)), 0);
  EXPECT_GT(coincident_pairs(voronoi::generate_level(shifted, 2)), 0);
  const std::vector<double> measures = voronoi::cell_measures_2d(voronoi::generate_level(shifted, 6));
  EXPECT_NEAR(sum(measures), 1.0, 1e-9);
  EXPECT_GT(max_error(measures, shifted.limit_measures), 5e-3);
  const Rules scaled_rules = voronoi::make_rules(2, 2, kExample, scaled());
  EXPECT_EQ(coincident_pairs(voronoi::generate_level(scaled_rules, 3)), 0);
}

TEST(VoronoiCells, Sum3D) {
  const Rules rules = voronoi::make_rules(3, 2, voronoi::random_points(3, 3, 99));
  for (int k = 0; k <= 3; ++k) {
    const std::vector<double> measures = voronoi::cell_measures_3d(voronoi::generate_level(rules, k));
    EXPECT_NEAR(sum(measures), 1.0, 1e-9) << "k " << k;
  }
}

TEST(VoronoiRandom, Deterministic) {
  const auto a = voronoi::random_points(3, 50, 42);
  EXPECT_EQ(a, voronoi::random_points(3, 50, 42));
  EXPECT_NE(a, voronoi::random_points(3, 50, 43));
  for (const auto& p : a)
    for (double x : p) EXPECT_TRUE(x >= 0 && x < 1);
  // The first value of xoshiro256** seeded through splitmix64 from 0, top 53 bits, from an independent
  // Python transcription of the reference algorithms.
  EXPECT_EQ(voronoi::random_points(1, 1, 0)[0][0], 0x1.33d8be6d96ebep-1);
}

}  // namespace
}  // namespace lacuna

namespace lacuna {
namespace {

TEST(VoronoiSpheres, RecipeInputPlacesOneSpherePerKeptGenerator) {
  // Level 2 of 3 starting points in 2D, d = 2: 48 generators; the spheres are those of colour 2
  // (counted from the level itself), tiled over 2 x 1 periods of 10 mm from the origin.
  const std::string text = R"({
    "inputs": {
      "g": {"type": "voronoi_spheres", "dimension": 2, "points": [[0.86, 0.3], [0.3, 0.65], [0.73, 0.85]],
            "level": 2, "period_mm": 10, "radius_mm": 0.5, "colours": [2], "tiles": [2, 1], "origin_mm": [1, 2, 3]}
    },
    "outputs": [{"of": "g", "file": "g.stl"}]
  })";
  Recipe recipe = parse_recipe(text, "spheres.json");
  const BuiltInput in = build_inputs(recipe).inputs[0];
  const nlohmann::json report = to_json(in.report);
  voronoi::RulesOptions options;
  options.children = voronoi::RulesOptions::Children::kScaled;
  const voronoi::Level level =
      voronoi::generate_level(voronoi::make_rules(2, 2, {{0.86, 0.3}, {0.3, 0.65}, {0.73, 0.85}}, options), 2);
  size_t colour2 = 0;
  for (int c : level.colours) colour2 += c == 1;
  EXPECT_EQ(report["points"], 48);
  ASSERT_EQ(in.geometry.spheres.centers_mm.size(), 2 * colour2);
  for (const Vec3d& p : in.geometry.spheres.centers_mm) {
    EXPECT_GE(p.x, 1);
    EXPECT_LT(p.x, 21);
    EXPECT_GE(p.y, 2);
    EXPECT_LT(p.y, 12);
    EXPECT_EQ(p.z, 3);
  }
}

}  // namespace
}  // namespace lacuna

namespace lacuna {
namespace {

// Volume of a closed polyhedron given as face loops (divergence theorem, orientation taken from the sign).
double piece_volume(const voronoi::ConvexPiece& piece) {
  double v = 0;
  for (const auto& f : piece.faces)
    for (size_t i = 1; i + 1 < f.size(); ++i) {
      const auto &a = f[0], &b = f[i], &c = f[i + 1];
      v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6;
    }
  return std::fabs(v);
}

double piece_area_2d(const voronoi::ConvexPiece& piece) {
  const auto& p = piece.faces[0];
  double a = 0;
  for (size_t i = 0; i < p.size(); ++i) a += p[i][0] * p[(i + 1) % p.size()][1] - p[i][1] * p[(i + 1) % p.size()][0];
  return a / 2;
}

// The spec's 2D example and four random 3D points, each with the (highest) level to test it at.
struct StartingSet {
  int n;
  std::vector<std::vector<double>> points;
  int level;
};

std::vector<StartingSet> starting_sets(int level_2d, int level_3d) {
  return {{2, kExample, level_2d}, {3, voronoi::random_points(3, 4, 11), level_3d}};
}

TEST(VoronoiWalls, ClosedForms) {
  // Two generators on a line: the walls are the two bisectors x = 1/2 and x = 0 (= 1), each of measure 1.
  for (int n : {2, 3}) {
    std::vector<std::vector<double>> points = {{0.25, 0.5}, {0.75, 0.5}};
    if (n == 3) points = {{0.25, 0.5, 0.5}, {0.75, 0.5, 0.5}};
    const Rules rules = voronoi::make_rules(n, 2, points, scaled());
    const voronoi::Walls walls = voronoi::extract_walls(rules, voronoi::generate_level(rules, 0));
    EXPECT_EQ(walls.facets.size(), 2u) << n;
    EXPECT_NEAR(walls.measure, 2.0, 1e-12) << n;
    EXPECT_EQ(walls.boundary_generators, 2u);
    for (const auto& f : walls.facets)
      for (const auto& v : f) EXPECT_NEAR(std::fabs(v[0] - 0.5), 0.5 * (std::fabs(v[0] - 0.5) > 0.25), 1e-12);
  }
  // One generator: no other colour, no wall.
  const Rules one = voronoi::make_rules(2, 3, {{0.4, 0.7}}, scaled());
  const voronoi::Walls none = voronoi::extract_walls(one, voronoi::generate_level(one, 2));
  EXPECT_EQ(none.points, 9u * 9u);
  EXPECT_TRUE(none.facets.empty());
  EXPECT_EQ(none.boundary_generators, 0u);
}

// The m-cell-shapes method against every generator's own clipped cell.
TEST(VoronoiWalls, ShapeMethodMatchesClipping) {
  for (const StartingSet& c : starting_sets(4, 2)) {
    const Rules rules = voronoi::make_rules(c.n, 2, c.points, scaled());
    for (int k = 0; k <= c.level; ++k) {
      const Level level = voronoi::generate_level(rules, k);
      const voronoi::Walls fast = voronoi::extract_walls(rules, level);
      const voronoi::Walls reference = voronoi::walls_by_clipping(level);
      EXPECT_EQ(fast.facets.size(), reference.facets.size()) << c.n << "D level " << k;
      EXPECT_EQ(fast.boundary_generators, reference.boundary_generators) << c.n << "D level " << k;
      EXPECT_NEAR(fast.measure, reference.measure, 1e-9 * reference.measure) << c.n << "D level " << k;
      if (k >= 2) {
        EXPECT_LT(fast.boundary_generators, fast.points);  // the skipped generators exist
      }
      // Every wall separates two different colours and a wall's colours are a pair of the colour graph.
      const auto graph = voronoi::colour_graph(level);
      for (const auto& pc : fast.colours) {
        EXPECT_NE(pc.first, pc.second);
        const std::pair<int, int> key{std::min(pc.first, pc.second), std::max(pc.first, pc.second)};
        EXPECT_TRUE(std::find(graph.begin(), graph.end(), key) != graph.end());
      }
    }
  }
  // The literal (shifted) children do not make a lattice: the fast method refuses them.
  const Rules shifted = voronoi::make_rules(2, 2, kExample);
  EXPECT_THROW(voronoi::extract_walls(shifted, voronoi::generate_level(shifted, 2)), InvalidInput);
}

// Refined tilings: a tile kept at level j is the union of the level-K cells of its generator's descendants, so
// its measure is, from the rules alone, sum_i (M^(K-j))[shape][i] |V_i| / d^(nK) (|V_i| the level-0 cell of
// p(i)); the tiles partition the torus; their walls (from the m cell shapes) equal those of clipping every cell.
TEST(VoronoiRefine, TilesPartitionTheTorusAndMatchTheRuleCounts) {
  for (const StartingSet& c : starting_sets(2, 1)) {
    const Rules rules = voronoi::make_rules(c.n, 2, c.points, scaled());
    const int detail = 1, levels = 2, last = detail + levels;
    // Refine the half x < 1/2 fully, the quarter 1/2 <= x < 3/4 once.
    const voronoi::RefinedLevel r = voronoi::refine_level(rules, detail, levels, [](const std::vector<double>& x, int l) {
      return x[0] < 0.5 || (x[0] < 0.75 && l == 0);
    });
    const size_t m = rules.points.size();
    const double dn = std::pow(2.0, c.n);
    ASSERT_EQ(r.level.points.size(), size_t(std::pow(dn, last)) * m);
    ASSERT_EQ(r.level.colour_count, int(r.tile_level.size()));
    int kept = 0;
    for (int t : r.tiles_per_level) kept += t;
    EXPECT_EQ(kept, r.level.colour_count);
    EXPECT_GT(r.tiles_per_level[2], 0);
    EXPECT_LT(r.tiles_per_level[2], r.level.colour_count);  // not every tile refined to the end
    const Level level0 = voronoi::generate_level(rules, 0);
    const std::vector<double> cell0 = c.n == 2 ? voronoi::cell_measures_2d(level0) : voronoi::cell_measures_3d(level0);
    const std::vector<double> tiles = c.n == 2 ? voronoi::cell_measures_2d(r.level) : voronoi::cell_measures_3d(r.level);
    EXPECT_NEAR(std::accumulate(tiles.begin(), tiles.end(), 0.0), 1.0, 1e-9) << c.n;
    std::vector<Eigen::MatrixXd> power(size_t(last) + 1, Eigen::MatrixXd::Identity(long(m), long(m)));
    for (int t = 1; t <= last; ++t) power[size_t(t)] = power[size_t(t) - 1] * rules.matrix;
    for (size_t t = 0; t < tiles.size(); ++t) {
      const int steps = last - r.tile_level[t];
      double expected = 0;
      for (size_t i = 0; i < m; ++i) expected += power[size_t(steps)](r.tile_shape[t], long(i)) * cell0[i];
      expected /= std::pow(dn, last);
      EXPECT_NEAR(tiles[t], expected, 1e-12) << c.n << "D tile " << t;
    }
    // The tiles of each starting colour make up that colour's cell of the unrefined last level.
    const Level plain = voronoi::generate_level(rules, last);
    const std::vector<double> colours = c.n == 2 ? voronoi::cell_measures_2d(plain) : voronoi::cell_measures_3d(plain);
    std::vector<double> by_colour(m, 0.0);
    for (size_t t = 0; t < tiles.size(); ++t) by_colour[size_t(r.tile_colour[t])] += tiles[t];
    for (size_t k = 0; k < m; ++k) EXPECT_NEAR(by_colour[k], colours[k], 1e-12) << c.n << "D colour " << k;
    const voronoi::Walls fast = voronoi::extract_walls(rules, r.level);
    const voronoi::Walls reference = voronoi::walls_by_clipping(r.level);
    EXPECT_EQ(fast.facets.size(), reference.facets.size()) << c.n;
    EXPECT_NEAR(fast.measure, reference.measure, 1e-9 * reference.measure) << c.n;
  }
  // Never refining gives the plain level detail + levels (the m fractal cells, the same walls); always refining
  // gives one tile per generator of level `levels`, each drawn with `detail` more levels.
  const Rules rules = voronoi::make_rules(2, 2, kExample, scaled());
  const voronoi::RefinedLevel none = voronoi::refine_level(rules, 1, 2, [](const std::vector<double>&, int) { return false; });
  const Level plain = voronoi::generate_level(rules, 3);
  EXPECT_EQ(none.level.colours, plain.colours);
  EXPECT_EQ(none.level.points, plain.points);
  EXPECT_EQ(none.tiles_per_level, (std::vector<int>{3, 0, 0}));
  EXPECT_EQ(voronoi::extract_walls(rules, none.level).measure, voronoi::extract_walls(rules, plain).measure);
  const voronoi::RefinedLevel all = voronoi::refine_level(rules, 1, 2, [](const std::vector<double>&, int) { return true; });
  EXPECT_EQ(all.level.colour_count, 3 * 16);
  EXPECT_EQ(all.tiles_per_level, (std::vector<int>{0, 0, 3 * 16}));
  EXPECT_THROW(voronoi::refine_level(rules, -1, 1, [](const std::vector<double>&, int) { return false; }), InvalidInput);
}

// The field is asked at each tile's generator where its compact tile lies: the unwrapped position, outside the
// unit period for a tile across the torus seam (a field read at the wrapped one would refine it elsewhere).
TEST(VoronoiRefine, TheFieldIsReadAtTheUnwrappedGenerator) {
  const Rules rules = voronoi::make_rules(2, 2, kExample, scaled());
  const Level one = voronoi::generate_level(rules, 1, true);
  ASSERT_EQ(one.unwrapped.size(), one.points.size());
  int outside = 0;
  for (const auto& u : one.unwrapped) outside += (u[0] < 0 || u[0] >= 1 || u[1] < 0 || u[1] >= 1);
  ASSERT_GT(outside, 0);  // some level-1 generators lie across the seam
  ASSERT_LT(outside, int(one.points.size()));
  std::vector<std::vector<double>> asked;
  const voronoi::RefinedLevel r = voronoi::refine_level(rules, 1, 2, [&](const std::vector<double>& x, int l) {
    if (l == 0) return true;
    asked.push_back(x);
    return x[0] < 0 || x[0] >= 1 || x[1] < 0 || x[1] >= 1;
  });
  EXPECT_EQ(asked, one.unwrapped);  // every level-1 generator asked once, in the recursion's order, unwrapped
  EXPECT_EQ(r.tiles_per_level, (std::vector<int>{0, int(one.points.size()) - outside, 4 * outside}));
}

// A refined tiling over several periods, each copy of a tile refined on its own. With choices that do not
// depend on the copy (read at the wrapped generator), every period holds refine_level's walls: twice the
// facets and measure over two periods. Read where each copy lies, the choices follow the field: a copy in the
// second period splits and one in the first does not, and the result moves with the field and the periods.
TEST(VoronoiRefine, CopiesOverPeriodsAreRefinedWhereTheyLie) {
  for (const StartingSet& c : starting_sets(2, 1)) {
    const Rules rules = voronoi::make_rules(c.n, 2, c.points, scaled());
    const int detail = 1, levels = 2;
    auto periodic_rule = [](const std::vector<double>& x, int l) {
      const double x0 = x[0] - std::floor(x[0]);
      return x0 < 0.5 || (x0 < 0.75 && l == 0);
    };
    const voronoi::Walls periodic = voronoi::extract_walls(rules, voronoi::refine_level(rules, detail, levels, periodic_rule).level);
    const std::array<int, 3> lo{0, 0, 0}, hi{2, 1, 1};
    const voronoi::RefinedWalls twice = voronoi::refined_walls(rules, detail, levels, lo, hi, periodic_rule);
    EXPECT_EQ(twice.walls.facets.size(), 2 * periodic.facets.size()) << c.n;
    EXPECT_NEAR(twice.walls.measure, 2 * periodic.measure, 1e-9 * periodic.measure) << c.n;
    for (const auto& f : twice.walls.facets)
      for (const auto& v : f) EXPECT_TRUE(v[0] > -0.5 && v[0] < 2.5) << c.n;

    // Split where x >= 1: the copies in the second period (level-0 generators are in [0, 1)) split, those
    // in the first do not.
    auto second = [](const std::vector<double>& x, int) { return x[0] >= 1; };
    const voronoi::RefinedWalls ramp = voronoi::refined_walls(rules, detail, 1, lo, hi, second);
    ASSERT_EQ(ramp.tiles_per_level.size(), 2u);
    EXPECT_GT(ramp.tiles_per_level[0], 0) << c.n;
    EXPECT_GT(ramp.tiles_per_level[1], 0) << c.n;
    const voronoi::RefinedWalls none = voronoi::refined_walls(rules, detail, 1, lo, hi, [](const std::vector<double>&, int) { return false; });
    const voronoi::RefinedWalls all = voronoi::refined_walls(rules, detail, 1, lo, hi, [](const std::vector<double>&, int) { return true; });
    EXPECT_EQ(none.tiles_per_level[1], 0);
    EXPECT_EQ(all.tiles_per_level[0], 0);
    // The first period's walls are those of no refinement, the second's those of full refinement, up to the
    // tiles that reach across the seams at x = 0, 1 and 2: the facets wholly within each period's middle.
    auto middle = [](const voronoi::Walls& w, double from) {
      double m = 0;
      for (size_t f = 0; f < w.facets.size(); ++f) {
        bool inside = true;
        for (const auto& v : w.facets[f]) inside = inside && v[0] > from + 0.3 && v[0] < from + 0.7;
        if (!inside) continue;
        const auto& q = w.facets[f];
        if (q.size() == 2) m += std::hypot(q[1][0] - q[0][0], q[1][1] - q[0][1]);
        else {
          std::array<double, 3> a{0, 0, 0};
          for (size_t k = 1; k + 1 < q.size(); ++k) {
            const double u[3] = {q[k][0] - q[0][0], q[k][1] - q[0][1], q[k][2] - q[0][2]};
            const double w2[3] = {q[k + 1][0] - q[0][0], q[k + 1][1] - q[0][1], q[k + 1][2] - q[0][2]};
            a[0] += u[1] * w2[2] - u[2] * w2[1];
            a[1] += u[2] * w2[0] - u[0] * w2[2];
            a[2] += u[0] * w2[1] - u[1] * w2[0];
          }
          m += 0.5 * std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        }
      }
      return m;
    };
    EXPECT_LT(middle(ramp.walls, 0), middle(all.walls, 0)) << c.n;   // coarse where x < 1
    EXPECT_GT(middle(ramp.walls, 1), middle(none.walls, 1)) << c.n;  // fine where x >= 1
    EXPECT_NEAR(middle(ramp.walls, 0), middle(none.walls, 0), 1e-9 * middle(none.walls, 0)) << c.n;
    EXPECT_NEAR(middle(ramp.walls, 1), middle(all.walls, 1), 1e-9 * middle(all.walls, 1)) << c.n;
    // The same field one period on, over the periods one on: the same walls one period on.
    auto moved = [](const std::vector<double>& x, int) { return x[0] - 1 >= 1; };
    const voronoi::RefinedWalls on = voronoi::refined_walls(rules, detail, 1, {1, 0, 0}, {3, 1, 1}, moved);
    ASSERT_EQ(on.walls.facets.size(), ramp.walls.facets.size()) << c.n;
    double worst = 0;
    for (size_t f = 0; f < on.walls.facets.size(); ++f)
      for (size_t k = 0; k < on.walls.facets[f].size(); ++k) {
        worst = std::max(worst, std::fabs(on.walls.facets[f][k][0] - 1 - ramp.walls.facets[f][k][0]));
        for (int j = 1; j < 3; ++j) worst = std::max(worst, std::fabs(on.walls.facets[f][k][size_t(j)] - ramp.walls.facets[f][k][size_t(j)]));
      }
    EXPECT_LT(worst, 1e-12) << c.n;
    EXPECT_EQ(on.tiles_per_level, ramp.tiles_per_level) << c.n;
  }
  // Bounds before allocating: too many periods, and periods times walls (a million periods of 2D walls).
  const Rules rules = voronoi::make_rules(2, 2, kExample, scaled());
  auto never = [](const std::vector<double>&, int) { return false; };
  EXPECT_THROW(voronoi::refined_walls(rules, 1, 1, {0, 0, 0}, {100000, 1000, 1}, never), ResourceLimit);
  EXPECT_THROW(voronoi::refined_walls(rules, 1, 1, {0, 0, 0}, {1000, 1000, 1}, never), ResourceLimit);
  EXPECT_THROW(voronoi::refined_walls(rules, 1, 1, {0, 0, 0}, {2, 1, 2}, never), InvalidInput);  // 2D: one period in z
}

// Without a gap the compact tiles hold exactly the cell measure of their colour, and together a fundamental
// domain of the torus (measure 1); with a gap, tiles + gap (wall measure x width) still make 1 up to the
// corners where walls meet.
TEST(VoronoiTiles, PiecesPartitionAFundamentalDomain) {
  for (const StartingSet& c : starting_sets(3, 2)) {
    const Rules rules = voronoi::make_rules(c.n, 2, c.points, scaled());
    const Level level = voronoi::generate_level(rules, c.level, true);
    const std::vector<double> measures =
        c.n == 2 ? voronoi::cell_measures_2d(level) : voronoi::cell_measures_3d(level);
    const voronoi::Walls walls = voronoi::extract_walls(rules, level);
    const double half_gap = 1e-3;
    double total = 0, total_gapped = 0;
    for (int colour = 0; colour < level.colour_count; ++colour) {
      double v = 0, vg = 0;
      for (const auto& piece : voronoi::tile_pieces(rules, level, colour, 0.0))
        v += c.n == 2 ? piece_area_2d(piece) : piece_volume(piece);
      for (const auto& piece : voronoi::tile_pieces(rules, level, colour, half_gap))
        vg += c.n == 2 ? piece_area_2d(piece) : piece_volume(piece);
      EXPECT_NEAR(v, measures[size_t(colour)], 1e-9) << c.n << "D colour " << colour;
      EXPECT_LT(vg, v);
      total += v;
      total_gapped += vg;
    }
    EXPECT_NEAR(total, 1.0, 1e-9);
    EXPECT_NEAR(total_gapped + walls.measure * 2 * half_gap, 1.0, 0.01);
  }
  const Rules rules = voronoi::make_rules(2, 2, kExample, scaled());
  EXPECT_THROW(voronoi::tile_pieces(rules, voronoi::generate_level(rules, 1), 0, 0.0), InvalidInput);
}

}  // namespace
}  // namespace lacuna
