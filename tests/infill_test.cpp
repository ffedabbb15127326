// Hull infill and printability: skins, lattices, grading, trapped voids and drain holes, thin
// walls, broken hulls, against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <set>

#include "errors.h"
#include "infill/bisection.h"
#include "infill/lattice.h"
#include "solids/check.h"
#include "solids/extract.h"
#include "solids/infill.h"
#include "solids/printability.h"
#include "solids/repair.h"
#include "solids/voxelize.h"
#include "tests/solid_fixtures.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

using test::box;

Volume ball(const Vec3d& c, double r, double h) {
  GeometrySet set;
  set.spheres.centers_mm = {c};
  set.spheres.radii_mm = {r};
  return voxelize(set, VolumeOptions{h, 3.0});
}

double mesh_volume(const Volume& v) { return check_mesh(extract_surface(v)).volume_mm3; }

TEST(Printability, SphereVoidIsTrappedUntilDrained) {
  const double h = 0.2, o = 0.1;  // faces half a voxel off the grid
  Volume part = subtract(box({o, o, o}, {20 + o, 20 + o, 20 + o}, h), ball({10 + o, 10 + o, 10 + o}, 5, h));
  PrintabilityOptions options;
  PrintabilityReport before = analyze_printability(part, options);
  ASSERT_EQ(before.trapped_voids.size(), 1u);
  const double sphere = 4.0 / 3.0 * kPi * 125;
  EXPECT_NEAR(before.trapped_voids[0].volume_mm3, sphere, 0.01 * sphere);
  EXPECT_LT(norm(before.trapped_voids[0].location_mm - Vec3d{10 + o, 10 + o, 10 + o}), 0.05);

  Volume drained = drill_drain_holes(part, before.trapped_voids, 2.0, options, /*downwards=*/true);
  EXPECT_TRUE(analyze_printability(drained, options).trapped_voids.empty());
  MeshCheckReport check = check_mesh(extract_surface(drained));
  EXPECT_TRUE(check.valid());
  EXPECT_EQ(check.genus, 0);
  // The channel of radius 1 runs from the sphere's surface to the bottom face, 10 mm from the
  // centre: its volume is the cylinder's less the sphere's cap inside it,
  // pi r^2 10 - (2 pi / 3)(R^3 - (R^2 - r^2)^(3/2)).
  const double hole = kPi * 10 - 2 * kPi / 3 * (125 - std::pow(24.0, 1.5));
  EXPECT_NEAR(mesh_volume(part) - check.volume_mm3, hole, 0.03 * hole);
}

TEST(Printability, ThinPlateIsReportedThickPlateIsNot) {
  const double h = 0.05, o = 0.025;
  PrintabilityOptions options;
  options.min_wall_mm = 0.4;
  Volume thin = box({o, o, o}, {6 + o, 6 + o, 0.3 + o}, h);
  PrintabilityReport r = analyze_printability(thin, options);
  ASSERT_EQ(r.thin_walls.size(), 1u);
  EXPECT_NEAR(r.thin_walls[0].volume_mm3, 6 * 6 * 0.3, 0.05 * 6 * 6 * 0.3);
  Volume thick = box({o, o, o}, {6 + o, 6 + o, 0.5 + o}, h);
  EXPECT_TRUE(analyze_printability(thick, options).thin_walls.empty());
}

TEST(Printability, ThinPlateIsThickenedByTheMinimumWall) {
  // A 0.3 mm plate under a 0.4 mm minimum wall grows by half the wall on every side: 0.3 + 0.4 mm
  // thick, and no longer thin. A thick block beside it is untouched.
  const double h = 0.05, o = 0.025;
  PrintabilityOptions options;
  options.min_wall_mm = 0.4;
  Volume plate = box({o, o, o}, {4 + o, 4 + o, 0.3 + o}, h);
  Volume block = box({6 + o, o, o}, {9 + o, 3 + o, 3 + o}, h);
  Volume part = unite(plate, block);
  PrintabilityReport r = analyze_printability(part, options);
  ASSERT_EQ(r.thin_walls.size(), 1u);
  Volume fixed = thicken_thin_walls(part, r, options.min_wall_mm);
  EXPECT_TRUE(analyze_printability(fixed, options).thin_walls.empty());
  MeshCheckReport check = check_mesh(extract_surface(fixed));
  ASSERT_TRUE(check.valid());
  EXPECT_EQ(check.components, 2u);
  // The plate's offset by 0.2 mm: (4.4 x 4.4 x 0.7) less the squared-off edges and corners an
  // offset rounds: box + faces + quarter cylinders + eighth spheres (Steiner's formula).
  const double d = 0.2, a = 4, b = 4, c = 0.3;
  const double grown = a * b * c + 2 * d * (a * b + b * c + a * c) + kPi * d * d * (a + b + c) + 4.0 / 3.0 * kPi * d * d * d;
  EXPECT_NEAR(check.volume_mm3, grown + 27, 0.02 * (grown + 27));
}

TEST(Printability, NarrowSlotIsASmallHole) {
  const double h = 0.05, o = 0.025;
  Volume block = box({o, o, o}, {6 + o, 4 + o, 3 + o}, h);
  Volume slot = box({2 + o, -1 + o, 1 + o}, {2.3 + o, 5 + o, 4 + o}, h);  // 0.3 mm wide, through
  PrintabilityOptions options;
  options.min_hole_mm = 0.5;
  PrintabilityReport r = analyze_printability(subtract(block, slot), options);
  ASSERT_EQ(r.small_holes.size(), 1u);
  EXPECT_NEAR(r.small_holes[0].volume_mm3, 0.3 * 4 * 2, 0.1 * 0.3 * 4 * 2);
  // Well below the slot's width (within a voxel or two of it the closing cannot decide).
  options.min_hole_mm = 0.1;
  EXPECT_TRUE(analyze_printability(subtract(block, slot), options).small_holes.empty());
}

TEST(Printability, OverhangOfABoxOnThePlate) {
  // A 10 mm cube standing on the plate has no overhang; turned upside down over a pillar, its
  // bottom (100 mm^2 less the pillar's 4 mm^2) is overhang.
  const double h = 0.1, o = 0.05;
  PrintabilityOptions options;
  EXPECT_NEAR(analyze_printability(box({o, o, o}, {10 + o, 10 + o, 10 + o}, h), options).overhang_area_mm2, 0, 1e-9);
  Volume table = unite(box({o, o, 5 + o}, {10 + o, 10 + o, 10 + o}, h), box({4 + o, 4 + o, o}, {6 + o, 6 + o, 5.2 + o}, h));
  EXPECT_NEAR(analyze_printability(table, options).overhang_area_mm2, 96, 0.02 * 96);
}

// Kuhn's grid of 4 x 3 x 2 cubes of side 2, bisected where a ramp along x wants cells down to a quarter of the
// side (six bisections) on the right: the tetrahedra still tile the grid (volumes add up to 48 mm^3), every
// bisection halves a volume (each tetrahedron is (8/6) / 2^depth), no two share a corner position twice, and
// the grid conforms: each triangle of a tetrahedron is a triangle of exactly one other, or lies on the grid's
// boundary. Every tetrahedron has at least the bisections the ramp wants at its centre, and the closure adds
// at most a few.
TEST(Infill, BisectedKuhnGridConformsAndFollowsTheField) {
  const int nx = 4, ny = 3, nz = 2;
  const double side = 2;
  auto index = [&](int i, int j, int k) { return uint32_t((k * (ny + 1) + j) * (nx + 1) + i); };
  std::vector<Vec3d> points;
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) points.push_back(Vec3d{double(i), double(j), double(k)} * side);
  std::vector<GridTet> tets;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const GridTet& t : kuhn_tetrahedra([&](int c) { return index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)); }))
          tets.push_back(t);
  ASSERT_EQ(tets.size(), size_t(6 * nx * ny * nz));
  auto wanted = [&](const Vec3d& p) { return int(std::lround(6 * std::clamp(p.x / (nx * side), 0.0, 1.0))); };
  std::vector<double> distances(points.size(), -1.0);  // everything is of interest
  size_t largest = 0;
  refine_grid_tets(points, distances, tets, wanted, [](const Vec3d&) { return -1.0; },
                   [&](size_t n) { largest = std::max(largest, n); });
  EXPECT_EQ(largest, tets.size());
  EXPECT_EQ(distances.size(), points.size());
  auto volume = [&](const GridTet& t) {
    const Vec3d &a = points[t.v[0]], &b = points[t.v[1]], &c = points[t.v[2]], &d = points[t.v[3]];
    return std::fabs(dot(b - a, cross(c - a, d - a))) / 6;
  };
  double total = 0;
  int deepest = 0;
  std::map<std::array<uint32_t, 3>, int> faces;
  for (const GridTet& t : tets) {
    const double v = volume(t);
    total += v;
    EXPECT_NEAR(v * std::ldexp(1.0, t.depth), side * side * side / 6, 1e-12);
    const Vec3d centre = (points[t.v[0]] + points[t.v[1]] + points[t.v[2]] + points[t.v[3]]) * 0.25;
    EXPECT_GE(t.depth, wanted(centre));
    EXPECT_LE(t.depth, wanted(centre) + 3);
    deepest = std::max(deepest, t.depth);
    for (int skip = 0; skip < 4; ++skip) {
      std::array<uint32_t, 3> f{};
      size_t n = 0;
      for (int q = 0; q < 4; ++q)
        if (q != skip) f[n++] = t.v[size_t(q)];
      std::sort(f.begin(), f.end());
      ++faces[f];
    }
  }
  EXPECT_NEAR(total, nx * ny * nz * side * side * side, 1e-9);
  EXPECT_EQ(deepest, 6);
  for (const auto& [f, n] : faces) {
    const Vec3d &a = points[f[0]], &b = points[f[1]], &c = points[f[2]];
    bool on_boundary = false;
    for (int axis = 0; axis < 3; ++axis) {
      const double top = axis == 0 ? nx * side : axis == 1 ? ny * side : nz * side;
      for (double plane : {0.0, top})
        on_boundary = on_boundary || (a[axis] == plane && b[axis] == plane && c[axis] == plane);
    }
    EXPECT_EQ(n, on_boundary ? 1 : 2) << a.x << " " << a.y << " " << a.z;
  }
  std::set<std::array<double, 3>> distinct;
  for (const Vec3d& p : points) distinct.insert({p.x, p.y, p.z});
  EXPECT_EQ(distinct.size(), points.size());
}

TEST(Infill, CubeHullWithLatticeSkinAndOnePart) {
  const double h = 0.2, o = 0.1, a = 20, s = 1.5;
  Volume hull = box({o, o, o}, {a + o, a + o, a + o}, h);
  // The skin alone: the cube minus the cube eroded by s.
  const double skin_exact = a * a * a - std::pow(a - 2 * s, 3);
  EXPECT_NEAR(mesh_volume(shell(hull, s)), skin_exact, 0.01 * skin_exact);
  LatticeOptions lattice;
  lattice.period_mm = 5;
  lattice.radius_mm = 0.6;
  Box3 region;
  region.expand(Vec3d{o, o, o});
  region.expand(Vec3d{a + o, a + o, a + o});
  GeometrySet struts;
  struts.tubes = lattice_tubes(region, lattice);
  Volume part = infill(hull, voxelize(struts, VolumeOptions{h, 3.0}), s, h);
  MeshCheckReport r = check_mesh(extract_surface(part));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  // One solid: every other surface component is a cavity (the space between skin and struts,
  // sealed inside it).
  PrintabilityReport p = analyze_printability(part, PrintabilityOptions{});
  EXPECT_EQ(r.components - p.trapped_voids.size(), 1u);
  EXPECT_GT(r.volume_mm3, skin_exact);
}

TEST(Infill, GradedLatticeDensityRisesAlongTheRamp) {
  const double h = 0.1, o = 0.05, a = 20;
  LatticeOptions lattice;
  lattice.period_mm = 4;
  lattice.radius_min_mm = 0.3;
  lattice.radius_max_mm = 1.1;
  lattice.grade.kind = GradeField::Kind::kRamp;
  lattice.grade.axis = {0, 0, 1};
  lattice.grade.from_mm = 0;
  lattice.grade.to_mm = a;
  Box3 region;
  region.expand(Vec3d{o, o, o});
  region.expand(Vec3d{a + o, a + o, a + o});
  GeometrySet struts;
  struts.tubes = lattice_tubes(region, lattice);
  Volume part = infill(box({o, o, o}, {a + o, a + o, a + o}, h), voxelize(struts, VolumeOptions{h, 3.0}), 1.0, h);
  // Density of the whole periods inside the skin (z from 4 to 16 mm), period by period, sampled
  // on a 0.1 mm grid.
  std::vector<double> density;
  for (int slab = 1; slab < 4; ++slab) {
    long inside = 0, total = 0;
    for (double z = slab * 4 + 0.05; z < (slab + 1) * 4; z += 0.1)
      for (double y = 1.55; y < a - 1.5; y += 0.1)
        for (double x = 1.55; x < a - 1.5; x += 0.1) {
          total++;
          inside += part.distance_at({x, y, z}) < 0;
        }
    density.push_back(double(inside) / double(total));
  }
  for (size_t i = 1; i < density.size(); ++i) EXPECT_GT(density[i], density[i - 1]) << "slab " << i;
  EXPECT_GT(density.back(), 2 * density.front());
}

double total_length(const TubeSet& set) {
  double sum = 0;
  for (const Tube& t : set.tubes)
    for (size_t i = 1; i < t.points_mm.size(); ++i) sum += norm(t.points_mm[i] - t.points_mm[i - 1]);
  return sum;
}

TEST(Infill, LevelGradeSplitsTheCellsUpTheRamp) {
  // Four unit cells along x, a ramp from 0 to 1 over them, one split allowed: the cells whose
  // centre is above 1/2 (the last two) become 2 x 2 x 2 cells of 0.5 mm. Edge lengths by hand:
  // the 2 x 1 x 1 unit block has 8 + 6 + 6 = 20 mm of edges, the 4 x 2 x 2 block of half cells
  // (36 + 30 + 30) x 0.5 = 48 mm; the unit edges on the face they share are distinct struts.
  LatticeOptions lattice;
  lattice.period_mm = 1;
  lattice.radius_mm = 0.1;
  lattice.graded = LatticeOptions::Graded::kLevel;
  lattice.levels = 1;
  lattice.grade.kind = GradeField::Kind::kRamp;
  lattice.grade.axis = {1, 0, 0};
  lattice.grade.from_mm = 0;
  lattice.grade.to_mm = 4;
  Box3 region;
  region.expand(Vec3d{0, 0, 0});
  region.expand(Vec3d{4, 1, 1});
  TubeSet struts = lattice_tubes(region, lattice);
  EXPECT_NEAR(total_length(struts), 68, 1e-9);
  EXPECT_EQ(struts.tubes.size(), 20u + 96u);
  for (const Tube& t : struts.tubes) EXPECT_EQ(t.radii_mm.front(), 0.1);
  // Without the grade: 4 x 1 x 1 unit cells, 16 + 10 + 10 mm.
  lattice.grade.kind = GradeField::Kind::kNone;
  EXPECT_NEAR(total_length(lattice_tubes(region, lattice)), 36, 1e-9);
}

TEST(Infill, ScaledLayoutSpansTheBoxWithWholeCells) {
  // 10 x 7 x 3 mm at a 3 mm period: 3 x 2 x 1 cells of 10/3 x 3.5 x 3 mm from the box's corner.
  LatticeOptions lattice;
  lattice.period_mm = 3;
  lattice.radius_mm = 0.2;
  lattice.layout = LatticeOptions::Layout::kScaled;
  Box3 region;
  region.expand(Vec3d{0.3, -1, 2});
  region.expand(Vec3d{10.3, 6, 5});
  TubeSet struts = lattice_tubes(region, lattice);
  // x edges 3 x 3 x 2 of 10/3, y edges 4 x 2 x 2 of 3.5, z edges 4 x 3 x 1 of 3.
  EXPECT_NEAR(total_length(struts), 60 + 56 + 36, 1e-9);
  Box3 nodes;
  for (const Tube& t : struts.tubes)
    for (const Vec3d& p : t.points_mm) nodes.expand(p);
  EXPECT_LT(norm(nodes.min - region.min), 1e-12);
  EXPECT_LT(norm(nodes.max - region.max), 1e-12);
}

TEST(Infill, ConformingLatticeEndsOnTheInsetSurface) {
  // A sphere hull of radius 9 with an inset of 1: every strut end lies inside radius 8, the ends
  // moved there lie on it, no strut runs between two moved ends, and the struts are one graph.
  const Vec3d c{0.37, 0.21, 0.13};
  const double radius = 9, inset = 1;
  LatticeOptions lattice;
  lattice.period_mm = 2;
  lattice.radius_mm = 0.3;
  lattice.layout = LatticeOptions::Layout::kConforming;
  lattice.conform_inset_mm = inset;
  HullFields hull;
  hull.signed_distance_mm = [&](const Vec3d& p) { return norm(p - c) - radius; };
  Box3 region;
  region.expand(c - Vec3d{radius, radius, radius});
  region.expand(c + Vec3d{radius, radius, radius});
  TubeSet struts = lattice_tubes(region, lattice, hull);
  ASSERT_GT(struts.tubes.size(), 100u);
  std::map<std::array<long, 3>, size_t> ids;
  std::vector<size_t> parent;
  auto id = [&](const Vec3d& p) {
    std::array<long, 3> key{std::lround(p.x * 1e6), std::lround(p.y * 1e6), std::lround(p.z * 1e6)};
    auto it = ids.find(key);
    if (it != ids.end()) return it->second;
    parent.push_back(parent.size());
    return ids[key] = parent.size() - 1;
  };
  std::function<size_t(size_t)> root = [&](size_t i) { return parent[i] == i ? i : parent[i] = root(parent[i]); };
  size_t on_surface = 0;
  for (const Tube& t : struts.tubes) {
    const double ra = norm(t.points_mm.front() - c), rb = norm(t.points_mm.back() - c);
    EXPECT_LE(ra, radius - inset + 1e-7);
    EXPECT_LE(rb, radius - inset + 1e-7);
    const bool a_moved = std::abs(ra - (radius - inset)) < 1e-7, b_moved = std::abs(rb - (radius - inset)) < 1e-7;
    EXPECT_FALSE(a_moved && b_moved);
    on_surface += a_moved + b_moved;
    parent[root(id(t.points_mm.front()))] = root(id(t.points_mm.back()));
  }
  EXPECT_GT(on_surface, 50u);
  size_t roots = 0;
  for (size_t i = 0; i < parent.size(); ++i) roots += root(i) == i;
  EXPECT_EQ(roots, 1u);
}

TEST(Infill, RepairsOnlyWhenAskedAndTheyWork) {
  // A cube with one face's triangles flipped and one vertex duplicated a hair away.
  TriMesh cube;
  for (int i = 0; i < 8; ++i) cube.positions_mm.push_back({i & 1 ? 10.0 : 0.0, i & 2 ? 10.0 : 0.0, i & 4 ? 10.0 : 0.0});
  cube.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  TriMesh broken = cube;
  std::swap(broken.triangles[2][1], broken.triangles[2][2]);
  std::swap(broken.triangles[3][1], broken.triangles[3][2]);
  broken.positions_mm.push_back({10.0, 10.0, 10.0 + 1e-6});
  broken.triangles[11][1] = 8;  // uses the near-duplicate of vertex 7
  EXPECT_FALSE(check_mesh(broken).valid());
  RepairOptions fix;
  fix.weld_mm = 1e-4;
  fix.reorient = true;
  TriMesh repaired = repair_mesh(broken, fix, 0.1);
  MeshCheckReport r = check_mesh(repaired);
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_NEAR(r.volume_mm3, 1000, 1e-6);
  // The top replaced by a lid 0.3 mm smaller all round: a crack of 0.3 mm, closed by a
  // morphological closing of 0.5 mm.
  TriMesh cracked = cube;
  cracked.triangles.erase(cracked.triangles.begin() + 2, cracked.triangles.begin() + 4);
  const uint32_t lid = uint32_t(cracked.positions_mm.size());
  for (Vec3d p : {Vec3d{0.3, 0.3, 10}, Vec3d{9.7, 0.3, 10}, Vec3d{9.7, 9.7, 10}, Vec3d{0.3, 9.7, 10}}) cracked.positions_mm.push_back(p);
  cracked.triangles.push_back({lid, lid + 1, lid + 2});
  cracked.triangles.push_back({lid, lid + 2, lid + 3});
  EXPECT_FALSE(check_mesh(cracked).closed());
  RepairOptions close;
  close.close_gaps_mm = 0.5;
  MeshCheckReport closed = check_mesh(repair_mesh(cracked, close, 0.1));
  EXPECT_TRUE(closed.valid()) << ::testing::PrintToString(closed.problems());
  EXPECT_NEAR(closed.volume_mm3, 1000, 0.02 * 1000);
  // A hole wider than the closing is refused, not turned into a thin cup.
  TriMesh open = cube;
  open.triangles.erase(open.triangles.begin() + 2, open.triangles.begin() + 4);
  EXPECT_THROW(repair_mesh(open, close, 0.1), InvalidInput);
}

}  // namespace
}  // namespace lacuna
