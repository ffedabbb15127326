// Space-filling curves turned into solids: tube volumes against independent integrals, recipe
// inputs on surfaces, small cavities, and the `curve` commands.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "curves/curves.h"
#include "curves/sweep.h"
#include "errors.h"
#include "pipeline/build_inputs.h"
#include "recipe/recipe.h"
#include "solids/check.h"
#include "solids/components.h"
#include "solids/extract.h"
#include "solids/voxelize.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

MeshCheckReport solid_of(const GeometrySet& set, double h) { return check_mesh(extract_surface(voxelize(set, VolumeOptions{h, 3.0}))); }

double distance_to_segment(double px, double py, const Vec3d& a, const Vec3d& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  const double t = std::clamp(((px - a.x) * dx + (py - a.y) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
  return std::hypot(px - a.x - t * dx, py - a.y - t * dy);
}

TEST(CurveSolids, StraightTubeIsACapsule) {
  GeometrySet set;
  set.tubes.tubes.push_back(Tube{{{0.03, 0.07, 0.01}, {12.03, 0.07, 0.01}}, {1.0}});
  const MeshCheckReport r = solid_of(set, 0.05);
  ASSERT_TRUE(r.valid());
  const double exact = kPi * 12 + 4.0 / 3.0 * kPi;
  EXPECT_NEAR(r.volume_mm3, exact, 0.01 * exact);
}

TEST(CurveSolids, PlanarHilbertSweepMatchesTheIntegralOfItsProfile) {
  // H_3 in a 20 mm square (step 2.5 mm) swept with r = 0.6 mm. The solid is every point within r
  // of the planar polyline: above a point of the plane at distance d < r from the curve it spans
  // 2 sqrt(r^2 - d^2) in z. That integral on a 0.02 mm grid is the independent value.
  curves::SweepOptions options;
  options.kind = curves::SweepOptions::Kind::kHilbert;
  options.orders = {3};
  options.radii_mm = {0.6};
  options.map.scale = 10;
  options.center_mm = {0.013, 0.021, 0.017};
  const curves::Sweep sweep = curves::sweep_curves(options, curves::plane_map());
  ASSERT_EQ(sweep.tubes.tubes.size(), 1u);
  const std::vector<Vec3d>& p = sweep.tubes.tubes[0].points_mm;
  ASSERT_EQ(p.size(), 64u);
  EXPECT_EQ(sweep.segments, 63u);
  const double r = 0.6, step = 0.02;
  double integral = 0;
  for (double y = -10; y < 10; y += step)
    for (double x = -10; x < 10; x += step) {
      const double px = x + step / 2 + options.center_mm.x, py = y + step / 2 + options.center_mm.y;
      double d = HUGE_VAL;
      for (size_t i = 1; i < p.size(); ++i) d = std::min(d, distance_to_segment(px, py, p[i - 1], p[i]));
      if (d < r) integral += 2 * std::sqrt(r * r - d * d) * step * step;
    }
  GeometrySet set;
  set.tubes = sweep.tubes;
  const MeshCheckReport solid = solid_of(set, 0.05);
  ASSERT_TRUE(solid.valid());
  EXPECT_EQ(solid.components, 1u);
  EXPECT_EQ(solid.genus, 0);
  EXPECT_NEAR(solid.volume_mm3, integral, 0.01 * integral);
  // And in closed form: segments 2.5 mm > 2r apart never meet except at their joints. At a
  // straight joint the cylinders continue flush; at a right-angle bend they overlap in a quarter of
  // the Steiner bicylinder (4r^3/3) and the ball adds the quarter outside both (pi r^3 / 3); the
  // two ends add half balls.
  int bends = 0;
  for (size_t i = 1; i + 1 < p.size(); ++i) bends += std::abs(dot(p[i] - p[i - 1], p[i + 1] - p[i])) < 1e-9;
  EXPECT_GT(bends, 0);
  const double exact = kPi * r * r * 63 * 2.5 + 4.0 / 3.0 * kPi * r * r * r - bends * (4.0 / 3.0 - kPi / 3) * r * r * r;
  EXPECT_NEAR(integral, exact, 0.002 * exact);
  EXPECT_NEAR(solid.volume_mm3, exact, 0.01 * exact);
}

TEST(CurveSolids, TubesLieOnTheMappedSurface) {
  curves::SweepOptions options;
  options.kind = curves::SweepOptions::Kind::kSierpinski;
  options.orders = {1, 2, 3};
  options.radii_mm = {0.5, 0.4, 0.3};
  options.map.scale = 7;
  options.map.offset_mm = 0.2;
  options.map.tolerance_mm = 0.03;
  options.center_mm = {1, 2, 3};
  const curves::Sweep torus = curves::sweep_curves(options, curves::torus_map());
  ASSERT_EQ(torus.tubes.tubes.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const Tube& t = torus.tubes.tubes[i];
    EXPECT_EQ(t.radii_mm.front(), options.radii_mm[i]);
    EXPECT_LT(norm(t.points_mm.front() - t.points_mm.back()), 1e-12);  // closed curves come back
    for (const Vec3d& q : t.points_mm) {
      // The offset torus: major radius 10.5 mm, minor 7 + 0.2 mm, about the z axis through the centre.
      const Vec3d d = q - options.center_mm;
      EXPECT_NEAR(std::hypot(std::hypot(d.x, d.y) - 10.5, d.z), 7.2, 1e-9);
    }
  }
  options.kind = curves::SweepOptions::Kind::kHilbert;
  options.base_thickness_mm = 1;
  const curves::Sweep sphere = curves::sweep_curves(options, curves::sphere_map());
  for (const Tube& t : sphere.tubes.tubes)
    for (const Vec3d& q : t.points_mm) EXPECT_NEAR(norm(q - options.center_mm), 7.2, 1e-9);
  ASSERT_EQ(sphere.base.size(), 1u);
  for (const Vec3d& q : sphere.base[0].surface.positions_mm) EXPECT_NEAR(norm(q - options.center_mm), 7, 1e-9);
  // The base's chords stay within the tolerance of the sphere.
  for (const auto& tri : sphere.base[0].surface.triangles) {
    const Vec3d m = (sphere.base[0].surface.positions_mm[tri[0]] + sphere.base[0].surface.positions_mm[tri[1]] +
                     sphere.base[0].surface.positions_mm[tri[2]]) * (1.0 / 3.0);
    EXPECT_LT(7 - norm(m - options.center_mm), 0.03);
  }
  options.radii_mm = {0.5, 0.4};
  EXPECT_THROW(curves::sweep_curves(options, curves::sphere_map()), InvalidInput);
}

TEST(CurveSolids, HilbertOnTheCubeIsOneClosedTubeWithNoGapAtTheEdges) {
  curves::SweepOptions options;
  options.kind = curves::SweepOptions::Kind::kHilbert;
  options.orders = {2};
  options.radii_mm = {0.5};
  options.map.scale = 5;
  const curves::Sweep cube = curves::sweep_curves(options, curves::SurfaceMap{}, /*on_cube=*/true);
  ASSERT_EQ(cube.tubes.tubes.size(), 1u);
  const Tube& t = cube.tubes.tubes[0];
  EXPECT_EQ(t.points_mm.size(), 6u * 16u + 6u + 1u);
  EXPECT_LT(norm(t.points_mm.front() - t.points_mm.back()), 1e-12);
  for (size_t i = 1; i < t.points_mm.size(); ++i) {
    const double step = norm(t.points_mm[i] - t.points_mm[i - 1]);
    EXPECT_TRUE(std::abs(step - 2.5) < 1e-12 || std::abs(step - 1.25) < 1e-12) << step;
  }
  GeometrySet set;
  set.tubes = cube.tubes;
  const MeshCheckReport r = solid_of(set, 0.1);
  ASSERT_TRUE(r.valid());
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.genus, 1);  // one closed loop of tube: a solid torus
}

TEST(CurveSolids, RecipeBsplinePatchOfDegreeOneIsThePlane) {
  // A bilinear patch on the corners of the 20 mm square is the plane map scaled by 10: the same
  // tube points, to rounding.
  const std::string text = R"({
    "inputs": {
      "patch": {"type": "curve", "kind": "sierpinski", "orders": "2..3", "surface": "bspline", "scale_mm": 1,
                "radius_mm": [0.4, 0.3],
                "patch": {"degree_u": 1, "degree_v": 1, "count_u": 2, "count_v": 2,
                          "control_points_mm": [[-10, -10, 0], [10, -10, 0], [-10, 10, 0], [10, 10, 0]]}},
      "plane": {"type": "curve", "kind": "sierpinski", "orders": [2, 3], "scale_mm": 10, "radius_mm": [0.4, 0.3]}
    },
    "outputs": [{"of": "patch", "file": "a.stl"}, {"of": "plane", "file": "b.stl"}]
  })";
  Recipe recipe = parse_recipe(text, "patch.json");
  ASSERT_EQ(recipe.inputs.size(), 2u);
  const BuiltInputs built = build_inputs(recipe);
  const TubeSet& a = recipe.inputs[0].name == "patch" ? built.inputs[0].geometry.tubes : built.inputs[1].geometry.tubes;
  const TubeSet& b = recipe.inputs[0].name == "patch" ? built.inputs[1].geometry.tubes : built.inputs[0].geometry.tubes;
  ASSERT_EQ(a.tubes.size(), 2u);
  ASSERT_EQ(b.tubes.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    ASSERT_EQ(a.tubes[i].points_mm.size(), b.tubes[i].points_mm.size());
    EXPECT_EQ(a.tubes[i].points_mm.size(), (size_t(1) << (2 * (i + 3))) + 1);  // 4^(k+1) segments, closed
    for (size_t j = 0; j < a.tubes[i].points_mm.size(); ++j) EXPECT_LT(norm(a.tubes[i].points_mm[j] - b.tubes[i].points_mm[j]), 1e-12);
  }
}

TEST(CurveSolids, SmallCavitiesAndSpecksAreRemovedLargeOnesKept) {
  // A 10 mm cube with two cube cavities (inward shells): 0.001 mm^3 and 1 mm^3.
  TriMesh m;
  auto add_box = [&](const Vec3d& lo, double a, bool inward) {
    const uint32_t base = uint32_t(m.positions_mm.size());
    for (int i = 0; i < 8; ++i) m.positions_mm.push_back(lo + Vec3d{i & 1 ? a : 0.0, i & 2 ? a : 0.0, i & 4 ? a : 0.0});
    const std::array<uint32_t, 3> faces[12] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                               {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (auto f : faces) {
      if (inward) std::swap(f[1], f[2]);
      m.triangles.push_back({base + f[0], base + f[1], base + f[2]});
    }
  };
  add_box({0, 0, 0}, 10, false);
  add_box({2, 2, 2}, 0.1, true);
  add_box({5, 5, 5}, 1, true);
  SmallShells removed = remove_small_shells(m, 0.01);
  EXPECT_EQ(removed.cavities, 1u);
  EXPECT_EQ(removed.specks, 0u);
  EXPECT_EQ(m.triangles.size(), 24u);
  EXPECT_EQ(m.positions_mm.size(), 16u);
  EXPECT_NEAR(signed_volume(m), 1000 - 1, 1e-9);
  removed = remove_small_shells(m, 0.01);
  EXPECT_EQ(removed.cavities + removed.specks, 0u);
  // Specks: a separate 0.001 mm^3 cube goes, a 1 mm^3 one stays; the cavity is no speck.
  add_box({20, 0, 0}, 0.1, false);
  add_box({30, 0, 0}, 1, false);
  removed = remove_small_shells(m, 0.01);
  EXPECT_EQ(removed.cavities, 0u);
  EXPECT_EQ(removed.specks, 1u);
  EXPECT_EQ(m.triangles.size(), 36u);
  EXPECT_NEAR(signed_volume(m), 1000 - 1 + 1, 1e-9);
  EXPECT_EQ(remove_small_shells(m, 0.01).specks, 0u);
}

}  // namespace
}  // namespace lacuna
