// Level sets, CSG, offsets and surface extraction against closed-form volumes and topology.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>

#include "errors.h"
#include "solids/check.h"
#include "solids/extract.h"
#include "solids/rasterize.h"
#include "solids/region.h"
#include "solids/voxelize.h"
#include "solids/volume.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

GeometrySet one_sphere(const Vec3d& c, double r) {
  GeometrySet set;
  set.spheres.centers_mm = {c};
  set.spheres.radii_mm = {r};
  return set;
}

MeshCheckReport mesh_and_check(const Volume& v) { return check_mesh(extract_surface(v)); }

double ball_volume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

TEST(Solids, SphereVolumeGenusComponents) {
  Volume v = voxelize(one_sphere({0.3, -0.2, 0.1}, 10.0), VolumeOptions{0.1, 3.0});
  MeshCheckReport r = mesh_and_check(v);
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_NEAR(r.volume_mm3, ball_volume(10), 0.005 * ball_volume(10));
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.components, 1u);
  // Surface area of the sphere, 4 pi r^2, as an independent measure of the surface's position.
  EXPECT_NEAR(r.area_mm2, 4 * kPi * 100, 0.01 * 4 * kPi * 100);
}

TEST(Solids, CapsuleMatchesClosedForm) {
  GeometrySet set;
  set.tubes.tubes.push_back(Tube{{{-4, 1, 0.3}, {4, -1, 0.7}}, {1.5}});
  const double length = std::sqrt(64.0 + 4.0 + 0.16);
  const double exact = kPi * 1.5 * 1.5 * length + ball_volume(1.5);
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.05, 3.0}));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_NEAR(r.volume_mm3, exact, 0.005 * exact);
  EXPECT_EQ(r.genus, 0);
}

// Convex hull of two balls (r1 > r2, centres L apart): the tangent cone touches the balls at
// axial offsets r1 s and L + r2 s (s = (r1 - r2) / L), so cap + frustum + cap.
double round_cone_volume(double r1, double r2, double length) {
  double s = (r1 - r2) / length;
  double c = std::sqrt(1 - s * s);
  auto cap = [](double r, double h) { return kPi * h * h * (3 * r - h) / 3; };
  double frustum_height = length - (r1 - r2) * s;
  double rho1 = r1 * c, rho2 = r2 * c;
  return cap(r1, r1 * (1 + s)) + kPi * frustum_height / 3 * (rho1 * rho1 + rho1 * rho2 + rho2 * rho2) +
         cap(r2, r2 * (1 - s));
}

TEST(Solids, TaperedTubeMatchesClosedForm) {
  GeometrySet set;
  set.tubes.tubes.push_back(Tube{{{0, 0, 0}, {0, 0, 8}}, {2.0, 1.0}});
  const double exact = round_cone_volume(2.0, 1.0, 8.0);
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.05, 3.0}));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_NEAR(r.volume_mm3, exact, 0.005 * exact);
}

// Distance in the plane from p to segment ab.
double segment_distance_2d(double px, double py, double ax, double ay, double bx, double by) {
  double dx = bx - ax, dy = by - ay;
  double t = std::clamp(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
  return std::hypot(px - ax - t * dx, py - ay - t * dy);
}

// A closed chain of 1000 capsules in the plane z = 0. Because every segment lies in that plane,
// the union over the point (x, y) is the interval |z| <= sqrt(r^2 - D^2), D the planar distance
// to the polyline: its volume is the plane integral of 2 sqrt(r^2 - D^2), computed here on a fine
// grid, independently of the rasterizer.
TEST(Solids, ChainOfThousandCapsulesMatchesFineReference) {
  const int n = 1000;
  const double r = 0.7;
  std::vector<Vec3d> points;
  for (int i = 0; i <= n; ++i) {
    double phi = 2 * kPi * (i % n) / n;
    double radius = 12 + 2.5 * std::sin(5 * phi);
    points.push_back({radius * std::cos(phi), radius * std::sin(phi), 0});
  }
  GeometrySet set;
  set.tubes.tubes.push_back(Tube{points, {r}});

  // Reference: midpoint rule at 0.01 mm with a bucket grid over the segments.
  const double step = 0.01, cell = 1.0;
  const double lo = -15.5, hi = 15.5;
  const int cells = int((hi - lo) / cell) + 1;
  std::vector<std::vector<int>> buckets(size_t(cells) * cells);
  for (int i = 0; i < n; ++i) {
    double x0 = std::min(points[i].x, points[i + 1].x) - r, x1 = std::max(points[i].x, points[i + 1].x) + r;
    double y0 = std::min(points[i].y, points[i + 1].y) - r, y1 = std::max(points[i].y, points[i + 1].y) + r;
    for (int cx = int((x0 - lo) / cell); cx <= int((x1 - lo) / cell); ++cx)
      for (int cy = int((y0 - lo) / cell); cy <= int((y1 - lo) / cell); ++cy) buckets[size_t(cx) * cells + cy].push_back(i);
  }
  long double reference = 0;
  for (double x = lo + step / 2; x < hi; x += step) {
    for (double y = lo + step / 2; y < hi; y += step) {
      const auto& bucket = buckets[size_t((x - lo) / cell) * cells + size_t((y - lo) / cell)];
      double d = r;
      for (int i : bucket) d = std::min(d, segment_distance_2d(x, y, points[i].x, points[i].y, points[i + 1].x, points[i + 1].y));
      if (d < r) reference += 2 * std::sqrt(r * r - d * d);
    }
  }
  reference *= step * step;

  MeshCheckReport m = mesh_and_check(voxelize(set, VolumeOptions{0.07, 3.0}));
  EXPECT_TRUE(m.valid()) << ::testing::PrintToString(m.problems());
  EXPECT_NEAR(m.volume_mm3, double(reference), 0.005 * double(reference));
  EXPECT_EQ(m.genus, 1);  // a closed chain is a solid torus
  EXPECT_EQ(m.components, 1u);
}

// Lens of two balls R and r at distance d (d < R + r).
double lens_volume(double big, double small, double d) {
  double s = big + small - d;
  return kPi * s * s * (d * d + 2 * d * small - 3 * small * small + 2 * d * big + 6 * small * big - 3 * big * big) /
         (12 * d);
}

TEST(Solids, UnionOfOverlappingSpheresMatchesLensFormula) {
  const VolumeOptions options{0.05, 3.0};
  Volume a = voxelize(one_sphere({0, 0, 0}, 3.0), options);
  Volume b = voxelize(one_sphere({3.5, 0.4, 0}, 2.0), options);
  const double d = std::hypot(3.5, 0.4);
  const double exact = ball_volume(3) + ball_volume(2) - lens_volume(3, 2, d);
  MeshCheckReport r = mesh_and_check(unite(a, b));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_NEAR(r.volume_mm3, exact, 0.005 * exact);
  // Intersection is the lens itself, difference what is left of a.
  MeshCheckReport lens = mesh_and_check(intersect(a, b));
  EXPECT_NEAR(lens.volume_mm3, lens_volume(3, 2, d), 0.01 * lens_volume(3, 2, d));
  MeshCheckReport rest = mesh_and_check(subtract(a, b));
  EXPECT_NEAR(rest.volume_mm3, ball_volume(3) - lens_volume(3, 2, d), 0.005 * ball_volume(3));
  // The same union rasterized in one grid.
  GeometrySet both = one_sphere({0, 0, 0}, 3.0);
  both.spheres.centers_mm.push_back({3.5, 0.4, 0});
  both.spheres.radii_mm = {3.0, 2.0};
  EXPECT_NEAR(mesh_and_check(voxelize(both, options)).volume_mm3, exact, 0.005 * exact);
}

TEST(Solids, ThickenedSquarePlate) {
  // The set within t/2 of a square of side a: slab a^2 t, half-cylinders along the four edges
  // (pi a t^2 / 2 in all) and a ball of radius t/2 from the four corners.
  const double a = 20.0, t = 1.0;
  TriMesh square{{{0, 0, 0}, {a, 0, 0}, {a, a, 0}, {0, a, 0}}, {{0, 1, 2}, {0, 2, 3}}};
  GeometrySet set;
  set.surfaces.push_back(ThickSurface{square, t});
  const double exact = a * a * t + kPi * a * t * t / 2 + kPi * t * t * t / 6;
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.1, 3.0}));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_NEAR(r.volume_mm3, exact, 0.01 * exact);
}

TEST(Solids, TorusHasGenusOne) {
  GeometrySet set;
  Shape torus;
  torus.kind = Shape::Kind::kTorus;
  torus.center_mm = {1, 2, 3};
  torus.axis = {0, 1, 1};
  torus.axis = torus.axis / norm(torus.axis);
  torus.radius_mm = 6;
  torus.minor_radius_mm = 1.5;
  set.shapes.push_back(torus);
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.1, 3.0}));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_EQ(r.genus, 1);
  EXPECT_EQ(r.components, 1u);
  const double exact = 2 * kPi * kPi * 6 * 1.5 * 1.5;
  EXPECT_NEAR(r.volume_mm3, exact, 0.005 * exact);
}

TEST(Solids, DisjointSpheresAreTwoComponents) {
  GeometrySet set = one_sphere({0, 0, 0}, 2.0);
  set.spheres.centers_mm.push_back({6, 0, 0});
  set.spheres.radii_mm = {2.0};
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.1, 3.0}));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.genus, 0);
  EXPECT_NEAR(r.volume_mm3, 2 * ball_volume(2), 0.005 * 2 * ball_volume(2));
}

TEST(Solids, BoxAndCylinderVolumes) {
  GeometrySet set;
  Shape box;
  box.kind = Shape::Kind::kBox;
  box.center_mm = {0.05, 0.02, 0};
  box.half_size_mm = {5, 3, 2};
  set.shapes.push_back(box);
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.1, 3.0}));
  EXPECT_TRUE(r.valid());
  EXPECT_NEAR(r.volume_mm3, 240.0, 0.005 * 240.0);
  GeometrySet cyl;
  Shape c;
  c.kind = Shape::Kind::kCylinder;
  c.axis = {1, 0, 0};
  c.radius_mm = 3;
  c.height_mm = 10;
  cyl.shapes.push_back(c);
  MeshCheckReport rc = mesh_and_check(voxelize(cyl, VolumeOptions{0.1, 3.0}));
  EXPECT_TRUE(rc.valid());
  EXPECT_NEAR(rc.volume_mm3, kPi * 9 * 10, 0.005 * kPi * 90);
}

TEST(Solids, OffsetsAndShellOfASphere) {
  const VolumeOptions options{0.1, 3.0};
  Volume ball = voxelize(one_sphere({0, 0, 0}, 5.0), options);
  EXPECT_NEAR(mesh_and_check(offset(ball, 1.0)).volume_mm3, ball_volume(6), 0.005 * ball_volume(6));
  EXPECT_NEAR(mesh_and_check(offset(ball, -1.5)).volume_mm3, ball_volume(3.5), 0.005 * ball_volume(3.5));
  MeshCheckReport hollow = mesh_and_check(shell(ball, 1.2));
  EXPECT_TRUE(hollow.valid()) << ::testing::PrintToString(hollow.problems());
  EXPECT_EQ(hollow.components, 2u);  // the outside and the sealed cavity, facing inward
  EXPECT_NEAR(hollow.volume_mm3, ball_volume(5) - ball_volume(3.8), 0.01 * (ball_volume(5) - ball_volume(3.8)));
  EXPECT_THROW(shell(ball, -1), InvalidInput);
}

// Several offsets from one distance computation (an infill's skin and core are made so): each is
// the closed form's offset ball, and the offset of a sphere-and-tube within 1e-4 of the separate
// offset's volume (OpenVDB widens a band by propagating nearest triangles, so the
// distances near a wider band's edge can differ by a fraction of a voxel).
TEST(Solids, OffsetsFromOneDistance) {
  const VolumeOptions options{0.1, 3.0};
  const std::vector<double> distances{-1.5, 0.0, -0.6, 0.8};
  const Volume ball = voxelize(one_sphere({0.02, -0.03, 0.01}, 4.0), options);
  const std::vector<Volume> balls = offsets(ball, distances);
  ASSERT_EQ(balls.size(), distances.size());
  for (size_t i = 0; i < distances.size(); ++i) {
    const MeshCheckReport r = mesh_and_check(balls[i]);
    EXPECT_TRUE(r.valid()) << distances[i] << ::testing::PrintToString(r.problems());
    EXPECT_NEAR(r.volume_mm3, ball_volume(4 + distances[i]), 0.005 * ball_volume(4 + distances[i])) << distances[i];
  }
  EXPECT_EQ(extract_surface(balls[1]).positions_mm, extract_surface(ball).positions_mm);

  GeometrySet set = one_sphere({0.3, 0, 0}, 3.0);
  set.tubes.tubes.push_back(Tube{{{-4, 1, 0.3}, {4, -1, 0.7}}, {1.2}});
  const Volume part = voxelize(set, options);
  const std::vector<Volume> together = offsets(part, distances);
  for (size_t i = 0; i < distances.size(); ++i) {
    const MeshCheckReport a = mesh_and_check(together[i]), b = mesh_and_check(offset(part, distances[i]));
    EXPECT_TRUE(a.valid()) << distances[i] << ::testing::PrintToString(a.problems());
    EXPECT_NEAR(a.volume_mm3, b.volume_mm3, 1e-4 * b.volume_mm3) << distances[i];
    EXPECT_EQ(a.components, b.components);
    EXPECT_EQ(a.genus, b.genus);
  }
  EXPECT_THROW(offsets(part, {-1.0, std::nan("")}), InvalidInput);
}

TEST(Solids, ClosedMeshToVolume) {
  // Octahedron |x| + |y| + |z| <= 4: volume 4/3 * 4^3.
  TriMesh octa;
  octa.positions_mm = {{4, 0, 0}, {-4, 0, 0}, {0, 4, 0}, {0, -4, 0}, {0, 0, 4}, {0, 0, -4}};
  for (uint32_t sx = 0; sx < 2; ++sx)
    for (uint32_t sy = 0; sy < 2; ++sy)
      for (uint32_t sz = 0; sz < 2; ++sz) {
        std::array<uint32_t, 3> t{sx, 2 + sy, 4 + sz};
        if ((sx + sy + sz) % 2 == 1) std::swap(t[1], t[2]);
        octa.triangles.push_back(t);
      }
  ASSERT_GT(signed_volume(octa), 0);
  GeometrySet set;
  set.solids.push_back(octa);
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.05, 3.0}));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_NEAR(r.volume_mm3, 4.0 / 3.0 * 64, 0.005 * 4.0 / 3.0 * 64);
}

// Offsets of a closed mesh from its own triangles: the octahedron |x| + |y| + |z| <= 4 shrunk by d is
// the octahedron of "radius" 4 - d sqrt(3); grown by d it has Steiner's volume V + S d + M d^2 + 4/3 pi d^3
// (S its area, M the sum over its 12 edges of length times the exterior dihedral angle over 2). The
// same as the offsets of its level set within the level set's own accuracy.
TEST(Solids, MeshOffsetsFromTheMeshItself) {
  TriMesh octa;
  octa.positions_mm = {{4, 0, 0}, {-4, 0, 0}, {0, 4, 0}, {0, -4, 0}, {0, 0, 4}, {0, 0, -4}};
  for (uint32_t sx = 0; sx < 2; ++sx)
    for (uint32_t sy = 0; sy < 2; ++sy)
      for (uint32_t sz = 0; sz < 2; ++sz) {
        std::array<uint32_t, 3> t{sx, 2 + sy, 4 + sz};
        if ((sx + sy + sz) % 2 == 1) std::swap(t[1], t[2]);
        octa.triangles.push_back(t);
      }
  const VolumeOptions options{0.05, 3.0};
  const std::vector<double> distances{-1.0, 0.5, -0.25};
  const std::vector<Volume> moved = mesh_offsets(octa, options, distances);
  ASSERT_EQ(moved.size(), distances.size());
  const double edge = 4 * std::sqrt(2.0), area = 2 * std::sqrt(3.0) * edge * edge;
  const double mean_width = 12 * edge * (kPi - std::acos(-1.0 / 3)) / 2;
  GeometrySet set;
  set.solids.push_back(octa);
  const Volume level_set = voxelize(set, options);
  for (size_t i = 0; i < distances.size(); ++i) {
    const double d = distances[i];
    const double r = 4 - std::max(-d, 0.0) * std::sqrt(3.0);
    const double exact = d < 0 ? 4.0 / 3.0 * r * r * r
                               : 4.0 / 3.0 * 64 + area * d + mean_width * d * d + 4.0 / 3.0 * kPi * d * d * d;
    const MeshCheckReport m = mesh_and_check(moved[i]);
    EXPECT_TRUE(m.valid()) << d << ::testing::PrintToString(m.problems());
    EXPECT_NEAR(m.volume_mm3, exact, 5e-4 * exact) << d;
    EXPECT_NEAR(m.volume_mm3, mesh_and_check(offset(level_set, d)).volume_mm3, 0.003 * exact) << d;
  }
  // A mesh with a cavity is not offset from its triangles (meshToVolume would fill the cavity).
  TriMesh hollow;
  auto cube = [&](double lo, double hi, bool inward) {
    const uint32_t base = uint32_t(hollow.positions_mm.size());
    for (int i = 0; i < 8; ++i) hollow.positions_mm.push_back({i & 1 ? hi : lo, i & 2 ? hi : lo, i & 4 ? hi : lo});
    const uint32_t f[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                               {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (const auto& t : f) hollow.triangles.push_back({base + t[0], base + (inward ? t[2] : t[1]), base + (inward ? t[1] : t[2])});
  };
  cube(0, 6, false);
  cube(2, 4, true);
  EXPECT_THROW(mesh_offsets(hollow, options, {-0.5}), InvalidInput);
  EXPECT_THROW(mesh_offsets(octa, options, {HUGE_VAL}), InvalidInput);
}

TEST(Solids, ClosedMeshWithCavityAndIsland) {
  // A cube of 12 around a cavity of 8 (facing inward) holding an island of 4: 1728 - 512 + 64.
  TriMesh m;
  auto cube = [&](double lo, double hi, bool inward) {
    uint32_t base = uint32_t(m.positions_mm.size());
    for (int i = 0; i < 8; ++i) m.positions_mm.push_back({i & 1 ? hi : lo, i & 2 ? hi : lo, i & 4 ? hi : lo});
    const uint32_t f[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                               {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    for (const auto& t : f) m.triangles.push_back({base + t[0], base + (inward ? t[2] : t[1]), base + (inward ? t[1] : t[2])});
  };
  cube(0.05, 12.05, false);
  cube(2.05, 10.05, true);
  cube(4.05, 8.05, false);
  ASSERT_TRUE(check_mesh(m).valid());
  GeometrySet set;
  set.solids.push_back(m);
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.1, 3.0}));
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.components, 3u);
  EXPECT_NEAR(r.volume_mm3, 1728 - 512 + 64, 0.005 * 1280);
}

TEST(Solids, ExtrudedRegionWithHole) {
  Region2 region;
  region.loops_mm = {{{0, 0}, {10, 0}, {10, 6}, {0, 6}}, {{2, 2}, {4, 2}, {4, 4}, {2, 4}}};
  region.height_mm = 1.5;
  EXPECT_DOUBLE_EQ(region_area_mm2(region), 56.0);
  TriMesh prism = extrude_region(region);
  EXPECT_NEAR(signed_volume(prism), 56.0 * 1.5, 1e-9);
  MeshCheckReport exact = check_mesh(prism);
  EXPECT_TRUE(exact.valid()) << ::testing::PrintToString(exact.problems());
  EXPECT_EQ(exact.genus, 1);
  GeometrySet set;
  set.regions.push_back(region);
  MeshCheckReport r = mesh_and_check(voxelize(set, VolumeOptions{0.05, 3.0}));
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(r.genus, 1);
  EXPECT_NEAR(r.volume_mm3, 84.0, 0.01 * 84.0);
  Region2 crossing;
  crossing.loops_mm = {{{0, 0}, {4, 4}, {4, 0}, {0, 4}}};  // a bow tie crosses itself
  EXPECT_THROW(extrude_region(crossing), InvalidInput);
}

TEST(Solids, SameResultForAnyThreadCount) {
  GeometrySet set;
  for (int i = 0; i < 40; ++i)
    set.tubes.tubes.push_back(Tube{{{std::cos(i * 0.7) * 4, std::sin(i * 0.7) * 4, i * 0.2}, {0, 0, i * 0.1}}, {0.4 + 0.01 * i}});
  TriMesh parallel = extract_surface(voxelize(set, VolumeOptions{0.08, 3.0}));
  TriMesh serial;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    serial = extract_surface(voxelize(set, VolumeOptions{0.08, 3.0}));
  }
  ASSERT_EQ(parallel.positions_mm.size(), serial.positions_mm.size());
  ASSERT_EQ(parallel.triangles.size(), serial.triangles.size());
  EXPECT_TRUE(parallel.positions_mm == serial.positions_mm);
  EXPECT_TRUE(parallel.triangles == serial.triangles);
}

TEST(Solids, RejectsBadGeometry) {
  GeometrySet bad = one_sphere({0, 0, 0}, -1.0);
  EXPECT_THROW(validate(bad), InvalidInput);
  GeometrySet nan = one_sphere({std::nan(""), 0, 0}, 1.0);
  EXPECT_THROW(validate(nan), InvalidInput);
  GeometrySet mismatch;
  mismatch.tubes.tubes.push_back(Tube{{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {0.1, 0.2}});
  EXPECT_THROW(validate(mismatch), InvalidInput);
  EXPECT_THROW(voxelize(one_sphere({0, 0, 0}, 1.0), VolumeOptions{0.0, 3.0}), InvalidInput);
}

TEST(Solids, EmptyVolumeGivesEmptyMesh) {
  Volume a = voxelize(one_sphere({0, 0, 0}, 1.0), VolumeOptions{0.1, 3.0});
  Volume b = voxelize(one_sphere({5, 0, 0}, 1.0), VolumeOptions{0.1, 3.0});
  EXPECT_TRUE(extract_surface(intersect(a, b)).triangles.empty());
  EXPECT_TRUE(intersect(a, b).empty());
}

}  // namespace
}  // namespace lacuna
