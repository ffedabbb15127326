// The combinatorics of a triangle mesh, in one place: half-edge pairing, edge and vertex
// manifoldness, boundary loops, connected components and Euler characteristics. The checks,
// patch flattening, components and repairs all read a mesh through this.
//
// Half-edge h = 3 * f + k of triangle f runs from its corner k to corner (k + 1) % 3.
#pragma once

#include <cstdint>
#include <vector>

#include "geometry.h"
#include "util/buffer.h"

namespace lacuna {

constexpr uint32_t kNoHalfEdge = UINT32_MAX;

inline uint32_t half_edge_from(const TriMesh& m, uint32_t h) { return m.triangles[h / 3][h % 3]; }
inline uint32_t half_edge_to(const TriMesh& m, uint32_t h) { return m.triangles[h / 3][(h % 3 + 1) % 3]; }
// The half-edge before h in its triangle (it ends where h starts).
inline uint32_t previous_half_edge(uint32_t h) { return 3 * (h / 3) + (h % 3 + 2) % 3; }
inline uint32_t next_half_edge(uint32_t h) { return 3 * (h / 3) + (h % 3 + 1) % 3; }

struct EdgeTopology {
  // The half-edge running the same edge the other way, when exactly two faces share the edge and
  // run it in opposite directions; kNoHalfEdge otherwise.
  Buffer<uint32_t> opposite;
  uint64_t edges = 0;               // distinct undirected edges (edges of repeated-corner faces aside)
  uint64_t boundary_edges = 0;      // one face
  uint64_t non_manifold_edges = 0;  // more than two faces
  uint64_t misoriented_edges = 0;   // two faces running it the same way
  // One half-edge of each problem edge, in increasing order (for messages naming the vertices).
  std::vector<uint32_t> boundary, non_manifold, misoriented;
  // Per vertex: the distinct edges whose smaller vertex it is (Euler characteristics per component).
  std::vector<uint32_t> low_edges;
  // When asked for: the other half-edge of every edge with exactly two faces, whichever way they
  // run it (repairs walk across misoriented edges too); kNoHalfEdge otherwise.
  std::vector<uint32_t> partner;

  bool clean() const { return boundary_edges == 0 && non_manifold_edges == 0 && misoriented_edges == 0; }
};

// The corners (3 * f + k) at every vertex: corners[offsets[v] .. offsets[v + 1]) in increasing order.
struct VertexCorners {
  Buffer<uint64_t> offsets;
  Buffer<uint32_t> corners;
  uint32_t degree(uint32_t v) const { return uint32_t(offsets[v + 1] - offsets[v]); }
};
VertexCorners vertex_corners(const TriMesh& mesh);

// Pairs the half-edges of the mesh (every index must name a vertex). Linear time, parallel,
// the same result for any number of threads.
EdgeTopology edge_topology(const TriMesh& mesh, const VertexCorners& corners, bool with_partners = false);
EdgeTopology edge_topology(const TriMesh& mesh, bool with_partners = false);

// How many fans (faces around a vertex joined across paired edges) each vertex has: 1 for a
// manifold vertex (interior or on the boundary), 0 for an unused one, more where fans only touch.
std::vector<uint32_t> vertex_fans(const TriMesh& mesh, const EdgeTopology& edges, const VertexCorners& corners);

// The boundary loops: each a list of vertices in the direction of its triangles' edges, starting
// at its smallest vertex, the loops in order of those. Requires a manifold boundary (no vertex
// where the boundary passes twice).
std::vector<std::vector<uint32_t>> boundary_loops(const TriMesh& mesh, const EdgeTopology& edges);

// Connected components through shared vertices: the component of every vertex (UINT32_MAX for
// unused ones), numbered in order of their smallest vertex.
struct VertexComponents {
  std::vector<uint32_t> of_vertex;
  uint32_t count = 0;
};
VertexComponents vertex_components(const TriMesh& mesh);

// Euler characteristic V - E + F of every component.
std::vector<int64_t> euler_characteristics(const TriMesh& mesh, const EdgeTopology& edges,
                                           const VertexComponents& components);

}  // namespace lacuna
