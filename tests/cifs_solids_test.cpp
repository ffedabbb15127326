// CIFS attractors turned into solids: Menger sponge, Sierpinski tetrahedron, NURBS shells, tube
// frames, against closed forms and counts.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "cifs/library.h"
#include "cifs/solid_input.h"
#include "cifs/tessellate.h"
#include "errors.h"
#include "recipe/cifs_system.h"
#include "solids/check.h"
#include "solids/extract.h"
#include "solids/rasterize.h"
#include "solids/voxelize.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

MeshCheckReport solid(const cifs::Cifs& c, int level, const cifs::SolidOptions& options, double voxel) {
  return check_mesh(extract_surface(voxelize(cifs::attractor_geometry(c, level, options), VolumeOptions{voxel, 3.0})));
}

// Faces half a voxel off the grid, so no plane passes through grid points.
cifs::Cifs placed(const std::string& name, double scale, double shift) {
  nlohmann::json spec = {{"library", name}, {"scale", scale}, {"translate_mm", {shift, shift, shift}}};
  return cifs::parse_system(spec, "test", "system");
}

TEST(CifsSolids, MengerSpongeGenusAndVolume) {
  const double side = 27, h = 1.0 / 3.0;
  const int genus[] = {0, 5, 81, 1409};
  for (int level = 1; level <= 3; ++level) {
    MeshCheckReport r = solid(placed("menger_sponge", side, h / 2), level, {}, h);
    EXPECT_TRUE(r.valid()) << level << ::testing::PrintToString(r.problems());
    EXPECT_EQ(r.components, 1u);
    EXPECT_EQ(r.genus, genus[level]) << "level " << level;
    const double exact = side * side * side * std::pow(20.0 / 27.0, level);
    EXPECT_NEAR(r.volume_mm3, exact, 0.005 * exact) << "level " << level;
  }
}

TEST(CifsSolids, SierpinskiTetrahedronHalvesItsVolumePerLevel) {
  const double edge = 30;
  const double v0 = edge * edge * edge / (6 * std::sqrt(2.0));
  for (int level = 0; level <= 3; ++level) {
    // 50 voxels along every piece's edge: marching tetrahedra cut the sharp edges by a fraction
    // of a voxel, which stays within 1 % at that resolution.
    const double h = edge / std::pow(2.0, level) / 50;
    MeshCheckReport r = solid(placed("sierpinski_tetrahedron", edge, h / 2), level, {}, h);
    EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
    const double exact = v0 / std::pow(2.0, level);
    EXPECT_NEAR(r.volume_mm3, exact, 0.01 * exact) << "level " << level;
  }
}

TEST(CifsSolids, FitToBoxScalesAndCentresTheAttractor) {
  // The Menger sponge is its unit cube; fitted to a 30 x 20 x 40 box it becomes a cube of side 20
  // (the smallest ratio) centred in the box.
  cifs::Cifs c = placed("menger_sponge", 1, 0);
  Box3 target;
  target.expand(Vec3d{-5, 0, 10});
  target.expand(Vec3d{25, 20, 50});
  cifs::Cifs fitted = cifs::fit_to_box(c, target);
  Box3 got;
  cifs::for_each_piece(fitted, 2, [&](const cifs::Piece& piece) {
    for (Eigen::Index i = 0; i < piece.vertices->cols(); ++i)
      got.expand(Vec3d{(*piece.vertices)(0, i), (*piece.vertices)(1, i), (*piece.vertices)(2, i)});
  });
  const Vec3d lo{0, 0, 20}, hi{20, 20, 40};
  EXPECT_LT(norm(got.min - lo), 1e-9);
  EXPECT_LT(norm(got.max - hi), 1e-9);
}

TEST(CifsSolids, StreamedBatchesGiveTheSameSolid) {
  cifs::Cifs c = placed("menger_sponge", 9, 0.05);
  cifs::SolidOptions whole, pieces;
  pieces.batch_pieces = 37;  // 400 cubes in 11 batches
  TriMesh a = extract_surface(voxelize(cifs::attractor_geometry(c, 2, whole), VolumeOptions{0.1, 3.0}));
  TriMesh b = extract_surface(voxelize(cifs::attractor_geometry(c, 2, pieces), VolumeOptions{0.1, 3.0}));
  EXPECT_TRUE(a.positions_mm == b.positions_mm);
  EXPECT_TRUE(a.triangles == b.triangles);
}

TEST(CifsSolids, MirroredCellsAreStillSolid) {
  // A cube whose corner order is mirrored (faces listed clockwise) rasterizes the same.
  ConvexCells cells;
  cells.corners_per_cell = 8;
  cells.faces = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  const double s = 4.05;
  cells.corners_mm = {{0.05, 0.05, 0.05}, {0.05, s, 0.05}, {s, s, 0.05}, {s, 0.05, 0.05},
                      {0.05, 0.05, s},    {0.05, s, s},    {s, s, s},    {s, 0.05, s}};
  GeometrySet set;
  set.cells.push_back(cells);
  MeshCheckReport r = check_mesh(extract_surface(voxelize(set, VolumeOptions{0.1, 3.0})));
  EXPECT_TRUE(r.valid());
  EXPECT_NEAR(r.volume_mm3, 64.0, 1e-3 * 64);  // the edges lose a chamfer of a fraction of a voxel
}

TEST(CifsSolids, ThickenedNurbsShellVolume) {
  // A gently curved bi-quadratic patch thickened to t: t times its area plus the half-cylinders
  // along its border, pi t^2 / 8 per unit of perimeter; both measured on a fine tessellation.
  nlohmann::json spec = {{"nurbs_surface", {{"u", {{"degree", 2}, {"knots", {0, 1, 2, 3}}}},
                                            {"v", {{"degree", 2}, {"knots", {0, 1, 2.5, 3}}}}}},
                         {"control_points_mm",
                          {{{0.03, 0.03, 0}, {0.03, 12, 1.5}, {0.03, 24, 0}},
                           {{12, 0.03, 1.5}, {12, 12, 3}, {12, 24, 1.5}},
                           {{24, 0.03, 0}, {24, 12, 1.5}, {24, 24, 0}}}}};
  cifs::Cifs c = cifs::parse_system(spec, "test", "system");
  const double t = 1.0;
  TriMesh fine = cifs::tessellate_surface(c, 8);
  const double area = surface_area(fine);
  // Perimeter: the border edges of the welded tessellation (used by one triangle only).
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const auto& tri : fine.triangles)
    for (int k = 0; k < 3; ++k) ++uses[{std::min(tri[k], tri[(k + 1) % 3]), std::max(tri[k], tri[(k + 1) % 3])}];
  double perimeter = 0;
  for (const auto& [edge, n] : uses)
    if (n == 1) perimeter += norm(fine.positions_mm[edge.first] - fine.positions_mm[edge.second]);
  cifs::SolidOptions options;
  options.thickness_mm = t;
  MeshCheckReport r = solid(c, 5, options, 0.1);
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_EQ(r.genus, 0);
  const double expected = area * t + kPi * t * t / 8 * perimeter;
  EXPECT_NEAR(r.volume_mm3, expected, 0.01 * expected);
}

TEST(CifsSolids, KochCurveAsTubes) {
  // A tube of radius r along the level-2 Koch curve (16 segments of 1/9 of 60 mm): genus 0, and
  // the volume of a capsule chain with small turning angles is close to pi r^2 L + 4/3 pi r^3.
  nlohmann::json spec = {{"library", "koch_curve"}, {"scale", 60}, {"translate_mm", {0.05, 0.05, 0.05}}};
  cifs::Cifs c = cifs::parse_system(spec, "test", "system");
  cifs::SolidOptions options;
  options.radius_mm = 0.8;
  MeshCheckReport r = solid(c, 2, options, 0.1);
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.components, 1u);
  const double length = 60 * std::pow(4.0 / 3.0, 2);
  const double tube = kPi * 0.64 * length + 4.0 / 3.0 * kPi * 0.512;
  // Corners of 60 and 120 degrees overlap or add wedges of order r^3: within 2 %.
  EXPECT_NEAR(r.volume_mm3, tube, 0.02 * tube);
}

TEST(CifsSolids, OptionsMustFitThePrimitives) {
  cifs::SolidOptions tubes;
  tubes.as = cifs::SolidOptions::As::kTubes;
  tubes.radius_mm = 1;
  EXPECT_THROW(cifs::attractor_geometry(cifs::library_system("menger_sponge"), 2, tubes), InvalidInput);
  cifs::SolidOptions shell;  // no thickness
  EXPECT_THROW(cifs::attractor_geometry(cifs::library_system("koch_curve"), 2, shell), InvalidInput);
  EXPECT_THROW(cifs::attractor_geometry(cifs::library_system("menger_sponge"), 8, {}), ResourceLimit);
}

TEST(CifsSolids, LevelsWhosePiecesAreFarBelowAVoxelAreRefused) {
  // The unit Sierpinski triangle's pieces at level L span 2^-L by 2^-L sqrt(3)/2: a box diagonal of
  // 2^-L sqrt(7)/2. With 0.1 mm voxels the first level under an eighth of a voxel is 7 (0.0103 mm;
  // level 6: 0.0207 mm); level 7 is accepted, level 8 and beyond refused, naming level 7.
  const cifs::Cifs triangle = cifs::library_system("sierpinski_triangle");
  cifs::SolidOptions edges;
  edges.as = cifs::SolidOptions::As::kEdges;
  edges.radius_mm = 0.1;
  edges.voxel_size_mm = 0.1;
  EXPECT_NO_THROW(cifs::attractor_geometry(triangle, 7, edges));
  for (int level : {8, 14}) {
    try {
      cifs::attractor_geometry(triangle, level, edges);
      ADD_FAILURE() << "level " << level << " was accepted";
    } catch (const InvalidInput& e) {
      const std::string diagonal = message_number(std::ldexp(std::sqrt(7.0) / 2, -level));
      EXPECT_NE(std::string(e.what()).find(" " + diagonal + " mm"), std::string::npos) << diagonal << ": " << e.what();
      EXPECT_NE(std::string(e.what()).find("use \"level\" 7 or less"), std::string::npos) << e.what();
    }
  }
  // Finer voxels allow finer levels; without a voxel size nothing is refused for this reason.
  edges.voxel_size_mm = 0.01;
  EXPECT_NO_THROW(cifs::attractor_geometry(triangle, 10, edges));
  edges.voxel_size_mm = 0;
  EXPECT_NO_THROW(cifs::attractor_geometry(triangle, 14, edges));
}

}  // namespace
}  // namespace lacuna
