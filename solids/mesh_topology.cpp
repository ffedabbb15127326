#include "solids/mesh_topology.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>

#include "solids/parallel_buffer.h"

namespace lacuna {

EdgeTopology edge_topology(const TriMesh& mesh, bool with_partners) {
  return edge_topology(mesh, vertex_corners(mesh), with_partners);
}

EdgeTopology edge_topology(const TriMesh& mesh, const VertexCorners& corners, bool with_partners) {
  const size_t nv = mesh.positions_mm.size(), nh = 3 * mesh.triangles.size();
  if (nh >= UINT32_MAX) throw std::length_error("a mesh with more than 1.4 billion triangles");
  EdgeTopology r;
  r.opposite = filled_buffer(nh, kNoHalfEdge);
  r.low_edges.assign(nv, 0);
  if (with_partners) r.partner.assign(nh, kNoHalfEdge);
  struct Counts {
    uint64_t edges = 0, boundary = 0, non_manifold = 0, misoriented = 0;
  };
  // Each edge {v, w} with v < w is settled at v: its half-edges are v -> w (a corner c at v whose
  // next corner is w) and w -> v (the half-edge before a corner at v whose previous corner is w).
  const size_t blocks = std::max<size_t>(1, std::min<size_t>(256, nv / 4096 + 1));
  std::vector<Counts> counts(blocks);
  std::vector<std::vector<uint32_t>> boundary(blocks), non_manifold(blocks), misoriented(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t block) {
    const size_t v0 = nv * block / blocks, v1 = nv * (block + 1) / blocks;
    Counts& c = counts[block];
    std::vector<uint64_t> keys;  // (other vertex << 32) | half-edge
    for (size_t v = v0; v < v1; ++v) {
      keys.clear();
      for (uint64_t i = corners.offsets[v]; i < corners.offsets[v + 1]; ++i) {
        const uint32_t corner = corners.corners[i];
        const auto& t = mesh.triangles[corner / 3];
        const uint32_t next = t[(corner % 3 + 1) % 3], previous = t[(corner % 3 + 2) % 3];
        if (next > v) keys.push_back((uint64_t(next) << 32) | corner);
        if (previous > v) keys.push_back((uint64_t(previous) << 32) | previous_half_edge(corner));
      }
      std::sort(keys.begin(), keys.end());
      for (size_t i = 0; i < keys.size();) {
        size_t j = i;
        while (j < keys.size() && (keys[j] >> 32) == (keys[i] >> 32)) ++j;
        const uint32_t h = uint32_t(keys[i]);
        ++c.edges;
        ++r.low_edges[v];
        const size_t n = j - i;
        if (n == 1) {
          ++c.boundary;
          boundary[block].push_back(h);
        } else if (n > 2) {
          ++c.non_manifold;
          non_manifold[block].push_back(h);
        } else {
          const uint32_t g = uint32_t(keys[i + 1]);
          if (with_partners) {
            r.partner[h] = g;
            r.partner[g] = h;
          }
          if (half_edge_from(mesh, h) == half_edge_from(mesh, g)) {
            ++c.misoriented;
            misoriented[block].push_back(h);
          } else {
            r.opposite[h] = g;
            r.opposite[g] = h;
          }
        }
        i = j;
      }
    }
  });
  for (size_t b = 0; b < blocks; ++b) {
    r.edges += counts[b].edges;
    r.boundary_edges += counts[b].boundary;
    r.non_manifold_edges += counts[b].non_manifold;
    r.misoriented_edges += counts[b].misoriented;
    r.boundary.insert(r.boundary.end(), boundary[b].begin(), boundary[b].end());
    r.non_manifold.insert(r.non_manifold.end(), non_manifold[b].begin(), non_manifold[b].end());
    r.misoriented.insert(r.misoriented.end(), misoriented[b].begin(), misoriented[b].end());
  }
  std::sort(r.boundary.begin(), r.boundary.end());
  std::sort(r.non_manifold.begin(), r.non_manifold.end());
  std::sort(r.misoriented.begin(), r.misoriented.end());
  return r;
}

VertexCorners vertex_corners(const TriMesh& mesh) {
  // A counting sort in parallel: counts and places by atomic increments, then each vertex's few
  // corners sorted (so the result is the same for any number of threads).
  VertexCorners r;
  const size_t nv = mesh.positions_mm.size(), nc = 3 * mesh.triangles.size();
  Buffer<uint32_t> count = filled_buffer(nv + 1, 0u);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nc, 16384), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t c = range.begin(); c != range.end(); ++c)
      __atomic_fetch_add(&count[mesh.triangles[c / 3][c % 3] + 1], 1u, __ATOMIC_RELAXED);
  });
  r.offsets = Buffer<uint64_t>(nv + 1);
  r.offsets[0] = 0;
  for (size_t v = 0; v < nv; ++v) r.offsets[v + 1] = r.offsets[v] + count[v + 1];
  r.corners = Buffer<uint32_t>(nc);
  Buffer<uint64_t> cursor = copied_buffer(r.offsets.data(), nv);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nc, 16384), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t c = range.begin(); c != range.end(); ++c)
      r.corners[__atomic_fetch_add(&cursor[mesh.triangles[c / 3][c % 3]], uint64_t{1}, __ATOMIC_RELAXED)] = uint32_t(c);
  });
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 8192), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t v = range.begin(); v != range.end(); ++v)
      std::sort(r.corners.data() + r.offsets[v], r.corners.data() + r.offsets[v + 1]);
  });
  return r;
}

std::vector<uint32_t> vertex_fans(const TriMesh& mesh, const EdgeTopology& edges, const VertexCorners& corners) {
  const size_t nv = mesh.positions_mm.size();
  std::vector<uint32_t> fans(nv, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<uint8_t> seen;
    for (size_t v = range.begin(); v != range.end(); ++v) {
      const uint32_t* first = corners.corners.data() + corners.offsets[v];
      const uint32_t* last = corners.corners.data() + corners.offsets[v + 1];
      const size_t d = size_t(last - first);
      if (d == 0) continue;
      seen.assign(d, 0);
      auto mark = [&](uint32_t corner) {
        const uint32_t* at = std::lower_bound(first, last, corner);
        if (at == last || *at != corner) return false;  // a repeated corner: no fan through it
        uint8_t& s = seen[size_t(at - first)];
        if (s) return false;
        s = 1;
        return true;
      };
      uint32_t count = 0;
      for (size_t i = 0; i < d; ++i) {
        if (seen[i]) continue;
        ++count;
        seen[i] = 1;
        // Around v: the corner at v in the face across the edge entering v, until the fan closes
        // or ends on a boundary; then the other way from the start.
        bool closed = false;
        for (uint32_t c = first[i];;) {
          const uint32_t across = edges.opposite[previous_half_edge(c)];
          if (across == kNoHalfEdge) break;
          if (across == first[i]) {
            closed = true;
            break;
          }
          if (!mark(across)) break;
          c = across;
        }
        if (closed) continue;
        for (uint32_t c = first[i];;) {
          const uint32_t across = edges.opposite[c];
          if (across == kNoHalfEdge) break;
          const uint32_t corner = next_half_edge(across);
          if (!mark(corner)) break;
          c = corner;
        }
      }
      fans[v] = count;
    }
  });
  return fans;
}

std::vector<std::vector<uint32_t>> boundary_loops(const TriMesh& mesh, const EdgeTopology& edges) {
  std::vector<uint32_t> next(mesh.positions_mm.size(), UINT32_MAX);
  for (uint32_t h : edges.boundary) next[half_edge_from(mesh, h)] = half_edge_to(mesh, h);
  std::vector<std::vector<uint32_t>> loops;
  std::vector<uint8_t> seen(mesh.positions_mm.size(), 0);
  for (uint32_t start = 0; start < next.size(); ++start) {
    if (next[start] == UINT32_MAX || seen[start]) continue;
    std::vector<uint32_t> loop;
    for (uint32_t w = start; w != UINT32_MAX && !seen[w]; w = next[w]) {
      seen[w] = 1;
      loop.push_back(w);
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

VertexComponents vertex_components(const TriMesh& mesh) {
  // Union-find joined concurrently: a root is linked only to a smaller root (by compare-and-swap,
  // retried when another join moved it first), so every set ends with its smallest vertex as root
  // whatever the order of the joins; the components are then numbered in order of their roots.
  const size_t nv = mesh.positions_mm.size(), nf = mesh.triangles.size();
  Buffer<uint32_t> parent(nv);
  Buffer<uint8_t> used(nv);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 65536), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t v = range.begin(); v != range.end(); ++v) {
      parent[v] = uint32_t(v);
      used[v] = 0;
    }
  });
  auto load = [&](uint32_t v) { return __atomic_load_n(&parent[v], __ATOMIC_RELAXED); };
  auto find = [&](uint32_t v) {
    for (;;) {
      const uint32_t p = load(v);
      if (p == v) return v;
      const uint32_t g = load(p);
      uint32_t expected = p;
      if (g != p)  // path halving; losing the race to another join leaves a valid ancestor either way
        __atomic_compare_exchange_n(&parent[v], &expected, g, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED);
      v = g;
    }
  };
  auto join = [&](uint32_t a, uint32_t b) {
    for (;;) {
      a = find(a);
      b = find(b);
      if (a == b) return;
      if (a < b) std::swap(a, b);
      uint32_t expected = a;
      if (__atomic_compare_exchange_n(&parent[a], &expected, b, false, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) return;
    }
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nf, 16384), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t f = range.begin(); f != range.end(); ++f) {
      const auto& t = mesh.triangles[f];
      join(t[0], t[1]);
      join(t[1], t[2]);
      for (uint32_t v : t) __atomic_store_n(&used[v], uint8_t{1}, __ATOMIC_RELAXED);
    }
  });
  // Every vertex straight to its root; the roots of used vertices counted in fixed blocks.
  const size_t blocks = nv / 65536 + 1;
  std::vector<uint32_t> roots(blocks + 1, 0);
  tbb::parallel_for(size_t(0), blocks, [&](size_t block) {
    uint32_t n = 0;
    for (size_t v = nv * block / blocks; v < nv * (block + 1) / blocks; ++v) {
      const uint32_t root = find(uint32_t(v));
      __atomic_store_n(&parent[v], root, __ATOMIC_RELAXED);  // other threads' finds read it
      n += used[v] && root == v;
    }
    roots[block + 1] = n;
  });
  for (size_t block = 0; block < blocks; ++block) roots[block + 1] += roots[block];
  VertexComponents r;
  r.count = roots[blocks];
  r.of_vertex.resize(nv);
  tbb::parallel_for(size_t(0), blocks, [&](size_t block) {
    uint32_t next = roots[block];
    for (size_t v = nv * block / blocks; v < nv * (block + 1) / blocks; ++v)
      r.of_vertex[v] = used[v] && parent[v] == v ? next++ : UINT32_MAX;
  });
  // A root is its set's smallest vertex: numbered above before any vertex of its set is read here.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 65536), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t v = range.begin(); v != range.end(); ++v)
      if (used[v] && parent[v] != v) r.of_vertex[v] = r.of_vertex[parent[v]];
  });
  return r;
}

std::vector<int64_t> euler_characteristics(const TriMesh& mesh, const EdgeTopology& edges,
                                           const VertexComponents& components) {
  std::vector<int64_t> euler(components.count, 0);
  for (size_t v = 0; v < components.of_vertex.size(); ++v) {
    const uint32_t c = components.of_vertex[v];
    if (c == UINT32_MAX) continue;
    euler[c] += 1 - int64_t(edges.low_edges[v]);
  }
  for (const auto& t : mesh.triangles) ++euler[components.of_vertex[t[0]]];
  return euler;
}

}  // namespace lacuna
