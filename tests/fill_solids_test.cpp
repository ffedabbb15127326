// Random fractal fillings turned into solids: perforated plates, wrapped panels and porous parts,
// against the exact volumes of what was placed.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "errors.h"
#include "fill/fill.h"
#include "fill/motif_solids.h"
#include "fill/wallpaper.h"
#include "pipeline/build_inputs.h"
#include "recipe/recipe.h"
#include "solids/check.h"
#include "solids/extract.h"
#include "solids/voxelize.h"
#include "tests/solid_fixtures.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

using test::box;

TEST(FillSolids, PerforatedPlateLosesExactlyTheHoles) {
  // Circles and hexagons placed in a 20 x 15 mm rectangle, 1 mm from its border, cut through a
  // 1.5 mm plate: the plate keeps 1.5 (300 - sum of the motif areas).
  const double h = 0.1, o = 0.05, t = 1.5;
  for (const fill::Motif2& motif : {fill::circle_motif(), fill::regular_polygon_motif(6)}) {
    fill::FillOptions f;
    f.c = 1.15;
    f.max_count = 25;
    f.gap_mm = 0.3;
    f.boundary_gap_mm = 1;
    f.seed = 11;
    f.random_rotation = true;
    const fill::FillResult2 r = fill::fill_region(fill::rectangle_region({o, o}, {20 + o, 15 + o}), motif, f);
    ASSERT_EQ(r.motifs.size(), 25u) << r.stop_reason;
    double holes = 0;
    for (const fill::Placement2& p : r.motifs) holes += p.area_mm2;
    EXPECT_NEAR(holes / 300, r.fill_fraction, 1e-12);
    fill::MotifSolidOptions solid;
    solid.height_mm = t + 2;
    solid.base_z_mm = -1;
    const Volume cutters = voxelize(fill::motif_solids(motif, r.motifs, solid), VolumeOptions{h, 3.0});
    const MeshCheckReport plate = check_mesh(extract_surface(subtract(box({o, o, o}, {20 + o, 15 + o, t + o}, h), cutters)));
    ASSERT_TRUE(plate.valid());
    EXPECT_EQ(plate.components, 1u);
    EXPECT_EQ(plate.genus, 25);
    const double exact = t * (300 - holes);
    EXPECT_NEAR(plate.volume_mm3, exact, 0.01 * exact);
  }
}

TEST(FillSolids, WrappedMotifsStandRadiallyOnTheCylinder) {
  // A p1 pattern of 3 cells of 10 mm wraps a cylinder of circumference 30 mm: radius 15 / pi.
  fill::FillOptions f;
  f.max_count = 10;
  f.gap_mm = 0.2;
  const fill::WallpaperFill pattern = fill::fill_wallpaper(fill::Group::p1, fill::Lattice{{10, 0}, {0, 10}}, fill::circle_motif(), f);
  const std::vector<fill::Placement2> all = fill::replicate(pattern, 3, 1);
  ASSERT_EQ(all.size(), 30u);
  fill::MotifSolidOptions solid;
  solid.wrap_radius_mm = 15 / kPi;
  solid.height_mm = 2;
  const GeometrySet set = fill::motif_solids(pattern.motif, all, solid);
  ASSERT_EQ(set.shapes.size(), 30u);
  for (size_t i = 0; i < all.size(); ++i) {
    const Shape& s = set.shapes[i];
    const double angle = all[i].center_mm.x / solid.wrap_radius_mm;
    EXPECT_NEAR(std::hypot(s.center_mm.x, s.center_mm.y), solid.wrap_radius_mm, 1e-12);
    EXPECT_NEAR(std::atan2(s.center_mm.y, s.center_mm.x), std::remainder(angle, 2 * kPi), 1e-12);
    EXPECT_NEAR(s.center_mm.z, all[i].center_mm.y, 1e-12);
    EXPECT_NEAR(dot(s.axis, Vec3d{std::cos(angle), std::sin(angle), 0}), 1, 1e-12);
    EXPECT_NEAR(s.radius_mm, std::sqrt(all[i].area_mm2 / kPi), 1e-12);
  }
}

TEST(FillSolids, PorousBoxPorosityIsThePlacedSphereVolume) {
  const std::string text = R"({
    "voxel_size_mm": 0.1,
    "inputs": {
      "pores": {"type": "fill_spheres", "box": {"min_mm": [0.05, 0.05, 0.05], "max_mm": [16.05, 16.05, 16.05]},
                "c": 1.1, "N": 3, "count": 30, "gap_mm": 0.5, "boundary_gap_mm": 0.8, "seed": 4}
    },
    "outputs": [{"of": "pores", "file": "p.stl"}]
  })";
  Recipe recipe = parse_recipe(text, "porous.json");
  const BuiltInput pores = build_inputs(recipe).inputs[0];
  const nlohmann::json report = to_json(pores.report);
  const SphereSet& s = pores.geometry.spheres;
  ASSERT_EQ(s.centers_mm.size(), 30u) << report.dump();
  EXPECT_EQ(report["spheres"], 30);
  double placed = 0;
  for (double r : s.radii_mm) placed += 4.0 / 3.0 * kPi * r * r * r;
  EXPECT_NEAR(placed / 4096, report["fill_fraction"].get<double>(), 1e-12);
  const double h = 0.1;
  const MeshCheckReport part = check_mesh(extract_surface(subtract(box({0.05, 0.05, 0.05}, {16.05, 16.05, 16.05}, h),
                                                                   voxelize(pores.geometry, VolumeOptions{h, 3.0}))));
  ASSERT_TRUE(part.valid());
  EXPECT_EQ(part.components, 31u);  // the box and 30 sealed pores
  const double porosity = 1 - part.volume_mm3 / 4096;
  EXPECT_NEAR(porosity, placed / 4096, 0.01 * placed / 4096);
}

TEST(FillSolids, BoxOfRotatedCubeInclusionsHasThePlacedVolume) {
  // Cubes placed by the volume rule, turned at random, kept apart: as convex cells their union's
  // volume is the sum of theirs.
  const std::string text = R"({
    "inputs": {
      "cubes": {"type": "fill_spheres", "motif": "cube", "random_rotation": true,
                "box": {"min_mm": [0.05, 0.05, 0.05], "max_mm": [12.05, 12.05, 12.05]},
                "c": 1.3, "N": 30, "count": 20, "gap_mm": 0.2, "boundary_gap_mm": 0.3, "seed": 9}
    },
    "outputs": [{"of": "cubes", "file": "c.stl"}]
  })";
  Recipe recipe = parse_recipe(text, "cubes.json");
  const BuiltInput in = build_inputs(recipe).inputs[0];
  const nlohmann::json report = to_json(in.report);
  ASSERT_EQ(in.geometry.cells.size(), 1u);
  const ConvexCells& cells = in.geometry.cells[0];
  ASSERT_EQ(cells.size(), 20u) << report.dump();
  const double zeta = fill::hurwitz_zeta(1.3, 30);
  double placed = 0;
  for (int i = 0; i < 20; ++i) placed += 1728 / (zeta * std::pow(30.0 + i, 1.3));
  EXPECT_NEAR(report["fill_fraction"].get<double>(), placed / 1728, 1e-12);
  const MeshCheckReport r = check_mesh(extract_surface(voxelize(in.geometry, VolumeOptions{0.05, 3.0})));
  ASSERT_TRUE(r.valid());
  EXPECT_EQ(r.components, 20u);
  EXPECT_NEAR(r.volume_mm3, placed, 0.01 * placed);
}

}  // namespace
}  // namespace lacuna
