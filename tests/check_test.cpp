// The validity checks: every kind of broken mesh is caught, and valid ones pass.
#include <gtest/gtest.h>

#include "solids/check.h"

namespace lacuna {
namespace {

// Octahedron |x - c| + |y - c| + |z - c| <= r, outward oriented: volume 4/3 r^3.
TriMesh octahedron(const Vec3d& c, double r, uint32_t first = 0) {
  TriMesh mesh;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {1.0, -1.0}) {
      Vec3d p = c;
      p[axis] += sign * r;
      mesh.positions_mm.push_back(p);
    }
  for (uint32_t sx = 0; sx < 2; ++sx)
    for (uint32_t sy = 0; sy < 2; ++sy)
      for (uint32_t sz = 0; sz < 2; ++sz) {
        std::array<uint32_t, 3> t{first + sx, first + 2 + sy, first + 4 + sz};
        if ((sx + sy + sz) % 2 == 1) std::swap(t[1], t[2]);
        mesh.triangles.push_back(t);
      }
  return mesh;
}

TriMesh merged(const TriMesh& a, const TriMesh& b) {
  TriMesh out = a;
  uint32_t offset = uint32_t(a.positions_mm.size());
  out.positions_mm.insert(out.positions_mm.end(), b.positions_mm.begin(), b.positions_mm.end());
  for (auto t : b.triangles) out.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return out;
}

TriMesh flipped(TriMesh m) {
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

TEST(Check, ValidOctahedron) {
  MeshCheckReport r = check_mesh(octahedron({0, 0, 0}, 3));
  EXPECT_TRUE(r.valid()) << ::testing::PrintToString(r.problems());
  EXPECT_DOUBLE_EQ(r.volume_mm3, 4.0 / 3.0 * 27);
  EXPECT_EQ(r.edges, 12u);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.genus, 0);
  EXPECT_TRUE(r.problems().empty());
}

TEST(Check, OpenMeshFails) {
  TriMesh m = octahedron({0, 0, 0}, 3);
  m.triangles.pop_back();
  MeshCheckReport r = check_mesh(m);
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.boundary_edges, 3u);
}

TEST(Check, FlippedFaceFails) {
  TriMesh m = octahedron({0, 0, 0}, 3);
  std::swap(m.triangles[2][1], m.triangles[2][2]);
  MeshCheckReport r = check_mesh(m);
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.misoriented_edges, 3u);
}

TEST(Check, InsideOutFails) {
  MeshCheckReport r = check_mesh(flipped(octahedron({0, 0, 0}, 3)));
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.inward_components, 1u);
  EXPECT_LT(r.volume_mm3, 0);
}

TEST(Check, NestedShellsNeedTheInnerOneInward) {
  TriMesh outer = octahedron({0, 0, 0}, 6);
  TriMesh good = merged(outer, flipped(octahedron({0.2, 0.1, 0}, 2)));
  MeshCheckReport ok = check_mesh(good);
  EXPECT_TRUE(ok.valid()) << ::testing::PrintToString(ok.problems());
  EXPECT_EQ(ok.components, 2u);
  EXPECT_NEAR(ok.volume_mm3, 4.0 / 3.0 * (216 - 8), 1e-9);
  MeshCheckReport bad = check_mesh(merged(outer, octahedron({0.2, 0.1, 0}, 2)));
  EXPECT_FALSE(bad.valid());
  EXPECT_EQ(bad.inward_components, 1u);
}

// Cube [-h, h]^3, each face split along the diagonal from (-,-) to (+,+) corners, outward.
TriMesh cube(double h) {
  TriMesh m;
  for (int i = 0; i < 8; ++i) m.positions_mm.push_back({i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

TEST(Check, NestingThroughAnEdgeIsCountedOnce) {
  // The inner octahedron's probe (the centroid of its first face) has y = z, so its ray along +x
  // runs exactly through the diagonal edge of the cube's +x face: one crossing, not two.
  TriMesh outer = cube(10);
  ASSERT_GT(check_mesh(outer).volume_mm3, 0);
  TriMesh inner = octahedron({1, 2, 2}, 3);
  MeshCheckReport good = check_mesh(merged(outer, flipped(inner)));
  EXPECT_TRUE(good.valid()) << ::testing::PrintToString(good.problems());
  EXPECT_EQ(good.inward_components, 0u);
  MeshCheckReport bad = check_mesh(merged(outer, inner));
  EXPECT_EQ(bad.inward_components, 1u);
  // Three levels: a solid island inside the cavity is outward again.
  TriMesh island = octahedron({1, 2, 2}, 1);
  MeshCheckReport three = check_mesh(merged(merged(outer, flipped(inner)), island));
  EXPECT_TRUE(three.valid()) << ::testing::PrintToString(three.problems());
  EXPECT_EQ(three.components, 3u);
}

TEST(Check, OverlappingShellsSelfIntersect) {
  MeshCheckReport r = check_mesh(merged(octahedron({0, 0, 0}, 3), octahedron({2, 0.3, 0.1}, 3)));
  EXPECT_TRUE(r.self_intersections_checked);
  EXPECT_TRUE(r.self_intersecting);
  EXPECT_FALSE(r.valid());
}

TEST(Check, DuplicatedFaceIsNonManifold) {
  TriMesh m = octahedron({0, 0, 0}, 3);
  m.triangles.push_back(m.triangles[0]);
  MeshCheckReport r = check_mesh(m);
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.non_manifold_edges, 3u);
}

TEST(Check, ShapesTouchingAtOneVertexAreNonManifold) {
  // Two octahedra sharing the vertex (3, 0, 0): two fans around one vertex.
  TriMesh a = octahedron({0, 0, 0}, 3);
  TriMesh b = octahedron({6, 0, 0}, 3);
  TriMesh m = merged(a, b);
  // Weld b's vertex (3, 0, 0) (its index 1 after the offset of 6) onto a's vertex 0.
  for (auto& t : m.triangles)
    for (auto& v : t)
      if (v == 7) v = 0;
  MeshCheckReport r = check_mesh(m);
  EXPECT_FALSE(r.valid());
  EXPECT_EQ(r.non_manifold_vertices, 1u);
}

TEST(Check, DegenerateAndNonFiniteFail) {
  TriMesh m = octahedron({0, 0, 0}, 3);
  m.positions_mm.push_back({0, 0, 0});
  m.positions_mm.push_back({1, 1, 1});
  m.positions_mm.push_back({2, 2, 2});
  m.triangles.push_back({6, 7, 8});  // collinear
  EXPECT_EQ(check_mesh(m).degenerate_faces, 1u);
  EXPECT_FALSE(check_mesh(m).valid());
  TriMesh n = octahedron({0, 0, 0}, 3);
  n.positions_mm[0].x = std::nan("");
  EXPECT_EQ(check_mesh(n).non_finite_vertices, 1u);
  EXPECT_FALSE(check_mesh(n).valid());
  TriMesh idx = octahedron({0, 0, 0}, 3);
  idx.triangles[0][0] = 99;
  EXPECT_EQ(check_mesh(idx).bad_indices, 1u);
  EXPECT_FALSE(check_mesh(TriMesh{}).valid());
}

TEST(Check, GenusOfATriangulatedTorus) {
  // A square torus: a 4 x 4 grid of quads on the torus, 32 triangles, genus 1.
  TriMesh m;
  const int n = 4;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double u = 2 * 3.14159265358979 * i / n, v = 2 * 3.14159265358979 * j / n;
      m.positions_mm.push_back({(5 + 2 * std::cos(v)) * std::cos(u), (5 + 2 * std::cos(v)) * std::sin(u), 2 * std::sin(v)});
    }
  auto id = [&](int i, int j) { return uint32_t(((i + n) % n) * n + (j + n) % n); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  MeshCheckReport r = check_mesh(m);
  EXPECT_EQ(r.genus, 1);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(r.boundary_edges, 0u);
  EXPECT_EQ(r.non_manifold_vertices, 0u);
}

}  // namespace
}  // namespace lacuna
