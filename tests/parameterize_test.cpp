// Flattening disk-like patches onto the square: a jittered planar grid (its corners, border, vertices
// and edge midpoints found again through the map), a tessellated hemisphere (points on its triangles,
// normals outwards, border on the equator), and the patches that are not disks.
#include "solids/parameterize.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "errors.h"
#include "mesh_fixtures.h"

namespace lacuna {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A reproducible value in [-1, 1] for an integer (a 32-bit integer hash; no std:: distributions).
double noise(uint32_t k) {
  k ^= k >> 16;
  k *= 0x7feb352dU;
  k ^= k >> 15;
  k *= 0x846ca68bU;
  k ^= k >> 16;
  return double(k) / double(UINT32_MAX) * 2 - 1;
}

// cells x cells quads over [0, side]^2 at z = 0, each split in two triangles (diagonals alternating),
// counter-clockwise seen from +z. Vertex (i, j) is j * (cells + 1) + i. Interior vertices move in the
// plane by up to a fifth of a cell per axis (no triangle flips), border vertices other than the 4 corners
// move along their side: the patch stays the square [0, side]^2.
TriMesh grid_patch(int cells, double side) {
  TriMesh mesh;
  double h = side / cells;
  for (int j = 0; j <= cells; ++j) {
    for (int i = 0; i <= cells; ++i) {
      uint32_t k = uint32_t(j * (cells + 1) + i);
      double dx = 0.2 * h * noise(2 * k), dy = 0.2 * h * noise(2 * k + 1);
      bool x_border = i == 0 || i == cells, y_border = j == 0 || j == cells;
      if (x_border) dx = 0;
      if (y_border) dy = 0;
      mesh.positions_mm.push_back({i * h + dx, j * h + dy, 0});
    }
  }
  test::append_grid_triangles(mesh, cells);
  return mesh;
}

// The upper half of a UV sphere of radius 1: the pole (vertex 0), then `rings` rings of `segments`
// vertices at polar angles i (pi/2) / rings, the last one the equator at z = 0 exactly; outward triangles.
TriMesh hemisphere_patch(int rings, int segments) {
  TriMesh mesh;
  mesh.positions_mm.push_back({0, 0, 1});
  for (int i = 1; i <= rings; ++i) {
    double theta = i * (kPi / 2) / rings;
    for (int j = 0; j < segments; ++j) {
      double phi = 2 * kPi * j / segments;
      double z = i == rings ? 0.0 : std::cos(theta);
      double r = i == rings ? 1.0 : std::sin(theta);
      mesh.positions_mm.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
  }
  auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * segments + (j % segments)); };
  for (int j = 0; j < segments; ++j) mesh.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
  for (int i = 1; i < rings; ++i) {
    for (int j = 0; j < segments; ++j) {
      uint32_t a = ring(i, j), b = ring(i + 1, j), c = ring(i + 1, j + 1), d = ring(i, j + 1);
      mesh.triangles.push_back({a, b, c});
      mesh.triangles.push_back({a, c, d});
    }
  }
  return mesh;
}

double signed_area(const Vec2d& a, const Vec2d& b, const Vec2d& c) {
  return 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

// Vertices on edges with one triangle.
std::set<uint32_t> boundary_vertices(const TriMesh& mesh) {
  std::multiset<std::pair<uint32_t, uint32_t>> edges;
  for (const auto& t : mesh.triangles) {
    for (int c = 0; c < 3; ++c) edges.insert(std::minmax(t[c], t[(c + 1) % 3]));
  }
  std::set<uint32_t> result;
  for (const auto& e : edges) {
    if (edges.count(e) == 1) {
      result.insert(e.first);
      result.insert(e.second);
    }
  }
  return result;
}

void expect_near(const Vec3d& a, const Vec3d& b, double tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

std::string message_of(const TriMesh& mesh) {
  try {
    mesh_patch_map(mesh);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "(no InvalidInput thrown)";
}

TEST(FlattenPatch, GridGoesOntoTheSquareWithoutFoldsAndBorderOnBorder) {
  TriMesh grid = grid_patch(10, 4.0);
  std::vector<Vec2d> xy = flatten_patch(grid);
  ASSERT_EQ(xy.size(), grid.positions_mm.size());
  std::set<uint32_t> border = boundary_vertices(grid);
  ASSERT_EQ(border.size(), 40u);
  for (uint32_t v = 0; v < xy.size(); ++v) {
    EXPECT_TRUE(xy[v].x >= -1 && xy[v].x <= 1 && xy[v].y >= -1 && xy[v].y <= 1) << v;
    bool on_square_border = std::fabs(xy[v].x) == 1 || std::fabs(xy[v].y) == 1;
    EXPECT_EQ(on_square_border, border.count(v) == 1) << v;
  }
  double total = 0;
  for (const auto& t : grid.triangles) {
    double area = signed_area(xy[t[0]], xy[t[1]], xy[t[2]]);
    EXPECT_GT(area, 0);
    total += area;
  }
  EXPECT_NEAR(total, 4.0, 1e-12);  // the triangles tile the square once
}

TEST(FlattenPatch, UnusedVerticesGetNaN) {
  TriMesh grid = grid_patch(3, 1.0);
  grid.positions_mm.push_back({7, 7, 7});
  std::vector<Vec2d> xy = flatten_patch(grid);
  ASSERT_EQ(xy.size(), 17u);
  EXPECT_TRUE(std::isnan(xy[16].x) && std::isnan(xy[16].y));
  for (size_t v = 0; v < 16; ++v) EXPECT_TRUE(std::isfinite(xy[v].x) && std::isfinite(xy[v].y));
}

TEST(MeshPatchMap, GridCornersGoOntoThePatchCornersCounterClockwise) {
  TriMesh grid = grid_patch(10, 4.0);
  curves::SurfaceMap map = mesh_patch_map(grid, "grid");
  EXPECT_EQ(map.name, "grid");
  // The 4 corners turn by 90 degrees, the rest by less; the one with the lowest index comes first.
  expect_near(map.point(-1, -1), {0, 0, 0}, 1e-12);
  expect_near(map.point(1, -1), {4, 0, 0}, 1e-12);
  expect_near(map.point(1, 1), {4, 4, 0}, 1e-12);
  expect_near(map.point(-1, 1), {0, 4, 0}, 1e-12);
  // Outside the square: clamped onto it.
  expect_near(map.point(2, -3), {4, 0, 0}, 1e-12);
}

TEST(MeshPatchMap, GridVerticesAndEdgeMidpointsAreFoundAgain) {
  TriMesh grid = grid_patch(10, 4.0);
  std::vector<Vec2d> xy = flatten_patch(grid);
  curves::SurfaceMap map = mesh_patch_map(grid);
  for (uint32_t v = 0; v < xy.size(); ++v) expect_near(map.point(xy[v].x, xy[v].y), grid.positions_mm[v], 1e-12);
  // The map is linear on each flattened triangle: the midpoint of a flattened edge goes onto the edge's.
  for (const auto& t : grid.triangles) {
    for (int c = 0; c < 3; ++c) {
      uint32_t a = t[c], b = t[(c + 1) % 3];
      Vec3d mid = (grid.positions_mm[a] + grid.positions_mm[b]) * 0.5;
      expect_near(map.point(0.5 * (xy[a].x + xy[b].x), 0.5 * (xy[a].y + xy[b].y)), mid, 1e-12);
    }
  }
}

TEST(MeshPatchMap, GridImagesStayInThePlaneAndCoverThePatch) {
  TriMesh grid = grid_patch(10, 4.0);
  curves::SurfaceMap map = mesh_patch_map(grid);
  Box3 box;
  const int n = 200;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      double x = -1 + 2.0 * i / n, y = -1 + 2.0 * j / n;
      Vec3d p = map.point(x, y);
      EXPECT_NEAR(p.z, 0, 1e-12);
      EXPECT_TRUE(p.x >= -1e-12 && p.x <= 4 + 1e-12 && p.y >= -1e-12 && p.y <= 4 + 1e-12) << x << " " << y;
      expect_near(map.normal(x, y), {0, 0, 1}, 1e-12);
      box.expand(p);
      // The border of the square goes onto the border of the patch.
      if (i == 0 || i == n || j == 0 || j == n) {
        EXPECT_NEAR(std::min({p.x, p.y, 4 - p.x, 4 - p.y}), 0, 1e-12) << x << " " << y;
      }
    }
  }
  expect_near(box.min, {0, 0, 0}, 1e-12);
  expect_near(box.max, {4, 4, 0}, 1e-12);
}

TEST(MeshPatchMap, KeepsOrientation) {
  TriMesh grid = grid_patch(10, 4.0);
  curves::SurfaceMap map = mesh_patch_map(grid);
  const double h = 1e-3;
  for (int j = 1; j < 10; ++j) {
    for (int i = 1; i < 10; ++i) {
      double x = -1 + 0.2 * i + 0.013, y = -1 + 0.2 * j - 0.007;
      Vec3d dx = map.point(x + h, y) - map.point(x - h, y);
      Vec3d dy = map.point(x, y + h) - map.point(x, y - h);
      EXPECT_GT(dot(cross(dx, dy), map.normal(x, y)), 0) << x << " " << y;
    }
  }
}

TEST(MeshPatchMap, CopiesAreIdenticalAndOutliveTheOriginal) {
  TriMesh grid = grid_patch(6, 2.0);
  curves::SurfaceMap copy;
  {
    curves::SurfaceMap map = mesh_patch_map(grid);
    copy = map;
  }
  curves::SurfaceMap again = mesh_patch_map(grid);
  for (int j = 0; j <= 20; ++j) {
    for (int i = 0; i <= 20; ++i) {
      double x = -1 + 0.1 * i, y = -1 + 0.1 * j;
      EXPECT_EQ(copy.point(x, y), again.point(x, y));
      EXPECT_EQ(copy.normal(x, y), again.normal(x, y));
    }
  }
  EXPECT_TRUE(std::isnan(copy.point(NAN, 0).x));
}

TEST(MeshPatchMap, HemisphereImagesLieOnItsTrianglesWithOutwardNormals) {
  const int rings = 8, segments = 24;
  TriMesh cap = hemisphere_patch(rings, segments);
  // Fixture check: outward triangles.
  for (const auto& t : cap.triangles) {
    const auto& p = cap.positions_mm;
    ASSERT_GT(dot(cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]), p[t[0]] + p[t[1]] + p[t[2]]), 0);
  }
  // A triangle inscribed in the unit sphere lies no closer to the centre than its plane, at
  // sqrt(1 - R^2) for its circumradius R = abc / (4 area).
  double nearest = 1;
  for (const auto& t : cap.triangles) {
    const auto& p = cap.positions_mm;
    double a = norm(p[t[1]] - p[t[0]]), b = norm(p[t[2]] - p[t[1]]), c = norm(p[t[0]] - p[t[2]]);
    double area = 0.5 * norm(cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]));
    double r = a * b * c / (4 * area);
    nearest = std::min(nearest, std::sqrt(1 - r * r));
  }
  ASSERT_GT(nearest, 0.95);

  curves::SurfaceMap map = mesh_patch_map(cap, "cap");
  const int n = 80;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      double x = -1 + 2.0 * i / n, y = -1 + 2.0 * j / n;
      Vec3d p = map.point(x, y);
      EXPECT_GE(norm(p), nearest - 1e-12) << x << " " << y;
      EXPECT_LE(norm(p), 1 + 1e-12) << x << " " << y;
      EXPECT_GE(p.z, -1e-12);
      Vec3d normal = map.normal(x, y);
      EXPECT_NEAR(norm(normal), 1, 1e-12);
      EXPECT_GT(dot(normal, p), 0) << x << " " << y;
      if (i == 0 || i == n || j == 0 || j == n) {
        EXPECT_NEAR(p.z, 0, 1e-12) << x << " " << y;  // the square's border goes onto the equator
      } else {
        EXPECT_GT(p.z, 0) << x << " " << y;
      }
    }
  }
  // Every equator vertex turns alike: the lowest one, (1, 0, 0), is the first corner, the others follow a
  // quarter turn apart, counter-clockwise seen from above (the outside).
  expect_near(map.point(-1, -1), {1, 0, 0}, 1e-12);
  expect_near(map.point(1, -1), {0, 1, 0}, 1e-12);
  expect_near(map.point(1, 1), {-1, 0, 0}, 1e-12);
  expect_near(map.point(-1, 1), {0, -1, 0}, 1e-12);
}

TEST(MeshPatchMap, HemisphereVerticesAreFoundAgain) {
  TriMesh cap = hemisphere_patch(8, 24);
  std::vector<Vec2d> xy = flatten_patch(cap);
  curves::SurfaceMap map = mesh_patch_map(cap);
  for (uint32_t v = 0; v < xy.size(); ++v) expect_near(map.point(xy[v].x, xy[v].y), cap.positions_mm[v], 1e-12);
  for (const auto& t : cap.triangles) EXPECT_GT(signed_area(xy[t[0]], xy[t[1]], xy[t[2]]), 0);
}

TEST(MeshPatchMap, LongBoundaryCornersFollowTheSameRule) {
  // 300 equator vertices: only the 256 sharpest start, but all turn alike, so the lowest still comes first.
  TriMesh cap = hemisphere_patch(4, 300);
  curves::SurfaceMap map = mesh_patch_map(cap);
  expect_near(map.point(-1, -1), {1, 0, 0}, 1e-12);
  expect_near(map.point(1, -1), {0, 1, 0}, 1e-12);
  expect_near(map.point(1, 1), {-1, 0, 0}, 1e-12);
  expect_near(map.point(-1, 1), {0, -1, 0}, 1e-12);
}

TEST(MeshPatchMap, ClosedMeshIsRejected) {
  TriMesh tetrahedron;
  tetrahedron.positions_mm = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tetrahedron.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  EXPECT_THROW(mesh_patch_map(tetrahedron), InvalidInput);
  EXPECT_NE(message_of(tetrahedron).find("closed"), std::string::npos) << message_of(tetrahedron);
}

TEST(MeshPatchMap, AnnulusIsRejected) {
  TriMesh annulus;
  const int segments = 12;
  for (int j = 0; j < segments; ++j) {
    double phi = 2 * kPi * j / segments;
    annulus.positions_mm.push_back({std::cos(phi), std::sin(phi), 0});
    annulus.positions_mm.push_back({2 * std::cos(phi), 2 * std::sin(phi), 0});
  }
  for (uint32_t j = 0; j < segments; ++j) {
    uint32_t a = 2 * j, b = 2 * j + 1, c = 2 * ((j + 1) % segments) + 1, d = 2 * ((j + 1) % segments);
    annulus.triangles.push_back({a, b, c});
    annulus.triangles.push_back({a, c, d});
  }
  EXPECT_NE(message_of(annulus).find("2 boundary loops"), std::string::npos) << message_of(annulus);
}

TEST(MeshPatchMap, DisjointTrianglesAreRejected) {
  TriMesh two;
  two.positions_mm = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 0, 0}, {6, 0, 0}, {5, 1, 0}};
  two.triangles = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_THROW(flatten_patch(two), InvalidInput);
  EXPECT_NE(message_of(two).find("2 separate pieces"), std::string::npos) << message_of(two);
}

TEST(MeshPatchMap, NonManifoldPatchesAreRejected) {
  // Three triangles on the edge 0-1.
  TriMesh book;
  book.positions_mm = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  book.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  EXPECT_NE(message_of(book).find("not manifold at edge"), std::string::npos) << message_of(book);
  // Two triangles that share only vertex 0.
  TriMesh bowtie;
  bowtie.positions_mm = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
  EXPECT_NE(message_of(bowtie).find("not manifold at vertex 0"), std::string::npos) << message_of(bowtie);
  // Two triangles running their shared edge the same way.
  TriMesh flipped;
  flipped.positions_mm = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  flipped.triangles = {{0, 1, 2}, {0, 3, 2}};
  EXPECT_NE(message_of(flipped).find("inconsistently oriented"), std::string::npos) << message_of(flipped);
}

TEST(MeshPatchMap, PatchWithAHandleIsRejected) {
  // A torus of 8 x 6 quads with one quad removed: one boundary loop, Euler characteristic 0 - 1 = -1.
  TriMesh torus;
  const int nu = 8, nv = 6;
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
      torus.positions_mm.push_back({(2 + std::cos(v)) * std::cos(u), (2 + std::cos(v)) * std::sin(u), std::sin(v)});
    }
  }
  auto at = [&](int i, int j) { return uint32_t((j % nv) * nu + (i % nu)); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      if (i == 0 && j == 0) continue;
      torus.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      torus.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  EXPECT_NE(message_of(torus).find("Euler characteristic -1"), std::string::npos) << message_of(torus);
}

TEST(MeshPatchMap, TooShortBoundaryIsRejected) {
  TriMesh one;
  one.positions_mm = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  EXPECT_NE(message_of(one).find("boundary has 3 edges"), std::string::npos) << message_of(one);
}

TEST(MeshPatchMap, PatchWithMoreEarsThanCornersIsRejected) {
  // A decagon cut into 5 ears (v_2k-1, v_2k, v_2k+1 for odd tips v_2k+1) around a fanned pentagon. An ear's
  // three corners lie on one side of the square unless its tip is one of the square's 4 corners, so
  // whatever corners are chosen, at least one ear flattens to a segment.
  TriMesh decagon;
  for (int i = 0; i < 10; ++i) decagon.positions_mm.push_back({std::cos(kPi * i / 5), std::sin(kPi * i / 5), 0});
  for (uint32_t k = 0; k < 5; ++k) decagon.triangles.push_back({2 * k, 2 * k + 1, (2 * k + 2) % 10});
  for (uint32_t k = 1; k < 4; ++k) decagon.triangles.push_back({0, 2 * k, 2 * k + 2});
  EXPECT_NE(message_of(decagon).find("folds over or flattens"), std::string::npos) << message_of(decagon);
}

}  // namespace
}  // namespace lacuna
