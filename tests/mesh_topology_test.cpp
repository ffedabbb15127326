// Half-edge pairing, fans, boundary loops, components and Euler characteristics against counts
// from the definition on small meshes.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "solids/disjoint_sets.h"
#include "solids/mesh_topology.h"
#include "util/random.h"

namespace lacuna {
namespace {

// Octahedron: 6 vertices, 12 edges, 8 faces, Euler characteristic 2.
TriMesh octahedron() {
  TriMesh m;
  m.positions_mm = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (uint32_t sx = 0; sx < 2; ++sx)
    for (uint32_t sy = 0; sy < 2; ++sy)
      for (uint32_t sz = 0; sz < 2; ++sz) {
        std::array<uint32_t, 3> t{sx, 2 + sy, 4 + sz};
        if ((sx + sy + sz) % 2 == 1) std::swap(t[1], t[2]);
        m.triangles.push_back(t);
      }
  return m;
}

TEST(MeshTopology, ClosedOctahedron) {
  const TriMesh m = octahedron();
  const VertexCorners corners = vertex_corners(m);
  const EdgeTopology e = edge_topology(m, corners);
  EXPECT_TRUE(e.clean());
  EXPECT_EQ(e.edges, 12u);
  for (uint32_t h = 0; h < 24; ++h) {
    ASSERT_NE(e.opposite[h], kNoHalfEdge);
    EXPECT_EQ(e.opposite[e.opposite[h]], h);
    EXPECT_EQ(half_edge_from(m, e.opposite[h]), half_edge_to(m, h));
  }
  for (uint32_t fans : vertex_fans(m, e, corners)) EXPECT_EQ(fans, 1u);
  const VertexComponents c = vertex_components(m);
  EXPECT_EQ(c.count, 1u);
  EXPECT_EQ(euler_characteristics(m, e, c), std::vector<int64_t>{2});
  EXPECT_TRUE(boundary_loops(m, e).empty());
}

TEST(MeshTopology, OpenFanBowtieAndNonManifoldEdge) {
  // A square of four triangles around vertex 4: one boundary loop of four edges, Euler 1.
  TriMesh square;
  square.positions_mm = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 0}};
  square.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  EdgeTopology e = edge_topology(square);
  EXPECT_EQ(e.edges, 8u);
  EXPECT_EQ(e.boundary_edges, 4u);
  const auto loops = boundary_loops(square, e);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0], (std::vector<uint32_t>{0, 1, 2, 3}));
  const VertexComponents c = vertex_components(square);
  EXPECT_EQ(euler_characteristics(square, e, c), std::vector<int64_t>{1});
  for (uint32_t fans : vertex_fans(square, e, vertex_corners(square))) EXPECT_EQ(fans, 1u);

  // Two triangles touching at vertex 0 only: two fans there.
  TriMesh bowtie;
  bowtie.positions_mm = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
  e = edge_topology(bowtie);
  EXPECT_EQ(vertex_fans(bowtie, e, vertex_corners(bowtie))[0], 2u);

  // Three triangles on one edge, and two running an edge the same way.
  TriMesh book;
  book.positions_mm = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  book.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  e = edge_topology(book);
  EXPECT_EQ(e.non_manifold_edges, 1u);
  TriMesh twisted;
  twisted.positions_mm = book.positions_mm;
  twisted.triangles = {{0, 1, 2}, {0, 1, 3}};
  e = edge_topology(twisted);
  EXPECT_EQ(e.misoriented_edges, 1u);
  EXPECT_EQ(e.opposite[0], kNoHalfEdge);
}

// Components joined concurrently against a serial union-find: 200 000 random triangles over 400 000
// vertices (most of them join into a few large sets, many stay alone or unused), numbered in order of
// their smallest vertex, the same for one thread and for every core.
TEST(MeshTopology, ComponentsJoinedConcurrentlyAreTheSerialOnes) {
  TriMesh m;
  const uint32_t nv = 400000;
  m.positions_mm.assign(nv, Vec3d{0, 0, 0});
  Random random(11);
  for (int f = 0; f < 200000; ++f)
    m.triangles.push_back({uint32_t(random.next() % nv), uint32_t(random.next() % nv), uint32_t(random.next() % nv)});
  DisjointSets sets(nv);
  std::vector<uint8_t> used(nv, 0);
  for (const auto& t : m.triangles) {
    sets.join(t[0], t[1]);
    sets.join(t[1], t[2]);
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  std::vector<uint32_t> expected(nv, UINT32_MAX), of_root(nv, UINT32_MAX);
  uint32_t count = 0;
  for (uint32_t v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    const uint32_t root = sets.find(v);
    if (of_root[root] == UINT32_MAX) of_root[root] = count++;
    expected[v] = of_root[root];
  }
  EXPECT_GT(count, 1000u);  // many components, so numbering matters
  const VertexComponents all = vertex_components(m);
  EXPECT_EQ(all.count, count);
  EXPECT_EQ(all.of_vertex, expected);
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const VertexComponents single = vertex_components(m);
  EXPECT_EQ(single.count, count);
  EXPECT_EQ(single.of_vertex, expected);
}

}  // namespace
}  // namespace lacuna
