#include "solids/check.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "errors.h"
#include "solids/components.h"
#include "solids/exact.h"
#include "solids/mesh_topology.h"
#include "solids/parallel_buffer.h"
#include "util/progress.h"

namespace lacuna {
namespace {

// Orientation of (a, b, p) in the (y, z) projection, exact, with p moved by the infinitesimal
// (eps, eps^2) when it lies on the line ab (simulation of simplicity): two triangles sharing an
// edge then never both contain p, and a ray through a vertex or along an edge is counted once.
int orient_yz(const Vec3d& a, const Vec3d& b, const Vec3d& p) {
  int o = exact::orient2d(a.y, a.z, b.y, b.z, p.y, p.z);
  if (o != 0) return o;
  if (b.z != a.z) return b.z > a.z ? -1 : 1;
  return b.y > a.y ? 1 : (b.y < a.y ? -1 : 0);
}

// A repeated corner or three collinear corners (exact predicate).
bool degenerate_face(const TriMesh& mesh, const std::array<uint32_t, 3>& t) {
  return t[0] == t[1] || t[1] == t[2] || t[0] == t[2] ||
         exact::collinear(mesh.positions_mm[t[0]], mesh.positions_mm[t[1]], mesh.positions_mm[t[2]]);
}

// Whether the ray from p along +x crosses triangle abc (exact predicates).
bool ray_crosses(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& p) {
  int s = exact::orient2d(a.y, a.z, b.y, b.z, c.y, c.z);
  if (s == 0) return false;  // parallel to the ray
  if (orient_yz(a, b, p) != s || orient_yz(b, c, p) != s || orient_yz(c, a, p) != s) return false;
  int side = exact::orient3d(a, b, c, p);
  if (side == 0) return false;
  // The plane meets the ray ahead of p when p lies on the side the +x direction leaves.
  return side * s < 0;
}

// For every component, how many other components enclose it: the parity of the crossings of a
// ray from one of its points along +x with each other component. Triangles are matched to the
// probes through a grid over (y, z), so the cost is one pass over the triangles.
// The (probe, component) pairs whose ray from the probe along +x crosses the component's surface
// an odd number of times, sorted, a probe's own component (own[q]) aside.
std::vector<std::pair<uint32_t, uint32_t>> odd_crossings(const TriMesh& mesh, const std::vector<uint32_t>& component_of,
                                                         const std::vector<Vec3d>& probe,
                                                         const std::vector<uint32_t>& own) {
  const size_t nc = probe.size();
  if (nc == 0) return {};
  Box3 box;
  for (const Vec3d& p : probe) box.expand(p);
  const double cell = std::max({box.size().y, box.size().z, 1e-9}) / std::max(1.0, std::ceil(std::sqrt(double(nc))));
  auto cell_of = [&](double y, double z) {
    return std::make_pair(int64_t(std::floor((y - box.min.y) / cell)), int64_t(std::floor((z - box.min.z) / cell)));
  };
  std::unordered_map<uint64_t, std::vector<uint32_t>> probes_in_cell;
  auto key = [](int64_t i, int64_t j) { return (uint64_t(i + (int64_t(1) << 31)) << 32) | uint64_t(j + (int64_t(1) << 31)); };
  for (uint32_t c = 0; c < nc; ++c) {
    auto [i, j] = cell_of(probe[c].y, probe[c].z);
    probes_in_cell[key(i, j)].push_back(c);
  }
  // (probe, component whose surface its ray crosses) for every crossing, per block of triangles.
  const size_t nf = mesh.triangles.size();
  const size_t blocks = std::max<size_t>(1, std::min<size_t>(256, nf / 16384 + 1));
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> crossings(blocks);
  tbb::parallel_for(size_t(0), blocks, [&](size_t block) {
    auto& out = crossings[block];
    for (size_t f = nf * block / blocks; f < nf * (block + 1) / blocks; ++f) {
      const auto& t = mesh.triangles[f];
      const Vec3d &a = mesh.positions_mm[t[0]], &b = mesh.positions_mm[t[1]], &c = mesh.positions_mm[t[2]];
      double y0 = std::min({a.y, b.y, c.y}), y1 = std::max({a.y, b.y, c.y});
      double z0 = std::min({a.z, b.z, c.z}), z1 = std::max({a.z, b.z, c.z});
      if (y1 < box.min.y || y0 > box.max.y || z1 < box.min.z || z0 > box.max.z) continue;
      auto [i0, j0] = cell_of(std::max(y0, box.min.y), std::max(z0, box.min.z));
      auto [i1, j1] = cell_of(std::min(y1, box.max.y), std::min(z1, box.max.z));
      const uint32_t owner = component_of[t[0]];
      for (int64_t i = i0; i <= i1; ++i)
        for (int64_t j = j0; j <= j1; ++j) {
          auto it = probes_in_cell.find(key(i, j));
          if (it == probes_in_cell.end()) continue;
          for (uint32_t q : it->second)
            if (own[q] != owner && probe[q].x <= std::max({a.x, b.x, c.x}) && ray_crosses(a, b, c, probe[q]))
              out.push_back({q, owner});
        }
    }
  });
  std::vector<std::pair<uint32_t, uint32_t>> all, odd;
  for (const auto& c : crossings) all.insert(all.end(), c.begin(), c.end());
  std::sort(all.begin(), all.end());
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    while (j < all.size() && all[j] == all[i]) ++j;
    if ((j - i) % 2) odd.push_back(all[i]);
    i = j;
  }
  return odd;
}

std::vector<uint32_t> nesting_depths(const TriMesh& mesh, const std::vector<uint32_t>& component_of, size_t nc) {
  std::vector<uint32_t> depth(nc, 0);
  if (nc < 2) return depth;
  std::vector<Vec3d> probe(nc);
  std::vector<uint8_t> has_probe(nc, 0);
  for (const auto& t : mesh.triangles) {
    uint32_t c = component_of[t[0]];
    if (has_probe[c]) continue;
    probe[c] = (mesh.positions_mm[t[0]] + mesh.positions_mm[t[1]] + mesh.positions_mm[t[2]]) / 3.0;
    has_probe[c] = 1;
  }
  std::vector<uint32_t> own(nc);
  std::iota(own.begin(), own.end(), 0u);
  for (const auto& [q, c] : odd_crossings(mesh, component_of, probe, own)) ++depth[q];
  return depth;
}

// Whether the closed fan of faces around v is the graph of a function over one of the three
// coordinate planes: every face projects with the same strict orientation and the projected
// fan winds exactly once around v. Then its faces meet only in the edges and the vertex they
// share, so no pair of faces sharing v needs a test of its own. Exact: orientations by
// exact predicates, the winding by counting the steps that cross the ray from v along the first
// projected axis (all steps turn the same way by less than a half turn).
bool fan_is_graph(const TriMesh& mesh, const EdgeTopology& edges, uint32_t start_corner, uint32_t v) {
  Vec3d normal;
  const Vec3d& p = mesh.positions_mm[v];
  for (uint32_t c = start_corner, steps = 0;; ++steps) {
    const auto& t = mesh.triangles[c / 3];
    const Vec3d &a = mesh.positions_mm[t[0]], &b = mesh.positions_mm[t[1]], &d = mesh.positions_mm[t[2]];
    normal += cross(b - a, d - a);
    c = edges.opposite[previous_half_edge(c)];
    if (c == start_corner) break;
    if (c == kNoHalfEdge || steps > 4096) return false;
  }
  const int k = dominant_axis(normal);
  const int i = (k + 1) % 3, j = (k + 2) % 3;  // (i, j, k) right-handed
  const int sign = normal[k] > 0 ? 1 : -1;
  int crossings = 0;
  for (uint32_t c = start_corner;;) {
    const auto& t = mesh.triangles[c / 3];
    const uint32_t a = t[(c % 3 + 1) % 3], b = t[(c % 3 + 2) % 3];  // (v, a, b) counter-clockwise
    const Vec3d &pa = mesh.positions_mm[a], &pb = mesh.positions_mm[b];
    if (exact::orient2d(p[i], p[j], pa[i], pa[j], pb[i], pb[j]) != sign) return false;
    // Counter-clockwise in the projection seen from +k: a step from below the line through v to
    // on or above it crosses the ray along +i; clockwise (sign < 0) mirrors it.
    const bool a_low = pa[j] < p[j], b_low = pb[j] < p[j];
    if (sign > 0 ? (a_low && !b_low) : (!a_low && b_low)) ++crossings;
    c = edges.opposite[previous_half_edge(c)];
    if (c == start_corner) break;
  }
  return crossings == 1;
}

// Triangle boxes rounded outwards to float, so a box test never misses a touching pair.
struct FaceBox {
  float lo[3], hi[3];
};

// The float next to a finite or infinite f towards -inf or +inf: a step of its bit pattern (what
// std::nextafter does, inline: it runs six times for every face).
float next_float(float f, bool above) {
  if (f == 0) return above ? std::numeric_limits<float>::denorm_min() : -std::numeric_limits<float>::denorm_min();
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  bits += (f > 0) == above ? 1 : uint32_t(-1);
  std::memcpy(&f, &bits, sizeof f);
  return f;
}
float down(double v) {
  const float f = float(v);
  return double(f) > v ? next_float(f, false) : f;
}
float up(double v) {
  const float f = float(v);
  return double(f) < v ? next_float(f, true) : f;
}

// Whether any two faces meet other than in the vertices or edge they share (exact predicates).
// Broad phase: a uniform grid over the faces' boxes, every face listed in each cell its box
// overlaps; a pair whose boxes overlap is tested only in the cell holding the lowest corner of
// the boxes' overlap, so each candidate pair is tested once; inside a cell the faces are sorted by
// their boxes' lower x and each meets only those starting before it ends. Cells start at six
// times the typical face's width (the square root of the mean area: measured on a 2.1 M-face
// surface, the fewest instructions and the least memory to fill, against 1 to 8 times) and grow
// until the grid holds at most 8 cells and the lists 16 entries per face, so long or large faces
// among small ones cost a bounded number of entries. Pairs sharing a vertex whose fan is a graph over a coordinate plane need no test of
// their own (fan_is_graph). Faces listed in `skip` (degenerate ones, reported separately) take no
// part.
bool self_intersects(const TriMesh& mesh, const EdgeTopology& edges, const VertexCorners& corners,
                     const std::vector<uint8_t>& skip, Progress& progress) {
  const size_t nf = mesh.triangles.size(), nv = mesh.positions_mm.size();
  std::vector<uint8_t> graph_fan(nv, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t v = range.begin(); v != range.end(); ++v)
      if (corners.degree(uint32_t(v)) > 0)
        graph_fan[v] = fan_is_graph(mesh, edges, corners.corners[corners.offsets[v]], uint32_t(v));
  });
  // A face's box, made again where it is needed: cheaper than the fresh pages a stored box for every
  // face takes (measured on 18.65 M faces: the self-intersection pass 4.6 s -> 4.2 s, the check's
  // peak 1.83 GB -> 1.39 GB).
  auto box_of = [&](size_t f) {
    const auto& t = mesh.triangles[f];
    const Vec3d &p0 = mesh.positions_mm[t[0]], &p1 = mesh.positions_mm[t[1]], &p2 = mesh.positions_mm[t[2]];
    FaceBox b;
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = down(std::min({p0[k], p1[k], p2[k]}));
      b.hi[k] = up(std::max({p0[k], p1[k], p2[k]}));
    }
    return b;
  };
  // The boxes' extent and twice the area, in fixed blocks (the sum does not depend on the threads).
  struct Extent {
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    double area2 = 0;
  };
  const size_t extent_blocks = nf / 65536 + 1;
  std::vector<Extent> extents(extent_blocks);
  tbb::parallel_for(size_t(0), extent_blocks, [&](size_t block) {
    Extent& e = extents[block];
    for (size_t f = nf * block / extent_blocks; f < nf * (block + 1) / extent_blocks; ++f) {
      const FaceBox b = box_of(f);
      for (int k = 0; k < 3; ++k) {
        e.lo[k] = std::min(e.lo[k], double(b.lo[k]));
        e.hi[k] = std::max(e.hi[k], double(b.hi[k]));
      }
      const auto& t = mesh.triangles[f];
      e.area2 += norm(cross(mesh.positions_mm[t[1]] - mesh.positions_mm[t[0]], mesh.positions_mm[t[2]] - mesh.positions_mm[t[0]]));
    }
  });
  double origin[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, top[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  long double area2 = 0;
  for (const Extent& e : extents) {
    for (int k = 0; k < 3; ++k) {
      origin[k] = std::min(origin[k], e.lo[k]);
      top[k] = std::max(top[k], e.hi[k]);
    }
    area2 += e.area2;
  }
  const double span = std::max({top[0] - origin[0], top[1] - origin[1], top[2] - origin[2]});
  double cell = std::max(6 * std::sqrt(double(area2 / 2) / double(nf)), span * 1e-6);
  if (!(cell > 0)) cell = 1;
  int64_t dims[3];
  double inv_cell = 1 / cell;
  // Boxes start at the origin or above, so truncating is rounding down (one formula everywhere, so
  // every pass puts a box in the same cells).
  auto cell_of = [&](double v, int k) {
    return int64_t(std::min(std::max((v - origin[k]) * inv_cell, 0.0), double(dims[k] - 1)));
  };
  for (;;) {
    inv_cell = 1 / cell;
    double cells = 1;
    for (int k = 0; k < 3; ++k) {
      dims[k] = int64_t(std::floor((top[k] - origin[k]) * inv_cell)) + 1;
      cells *= double(dims[k]);
    }
    if (cells > 8.0 * double(nf) + 64) {
      cell *= 1.25;
      continue;
    }
    const uint64_t entries = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, nf, 8192), uint64_t{0},
        [&](const tbb::blocked_range<size_t>& range, uint64_t n) {
          for (size_t f = range.begin(); f != range.end(); ++f) {
            const FaceBox b = box_of(f);
            uint64_t m = 1;
            for (int k = 0; k < 3; ++k) m *= uint64_t(cell_of(b.hi[k], k) - cell_of(b.lo[k], k) + 1);
            n += m;
          }
          return n;
        },
        std::plus<uint64_t>());
    if (entries > 16 * uint64_t(nf) + 1024) {
      cell *= 1.5;
      continue;
    }
    break;
  }
  const size_t ncells = size_t(dims[0] * dims[1] * dims[2]);
  auto for_cells = [&](size_t f, auto&& visit) {
    const FaceBox b = box_of(f);
    const int64_t x0 = cell_of(b.lo[0], 0), x1 = cell_of(b.hi[0], 0), y0 = cell_of(b.lo[1], 1),
                  y1 = cell_of(b.hi[1], 1), z0 = cell_of(b.lo[2], 2), z1 = cell_of(b.hi[2], 2);
    for (int64_t x = x0; x <= x1; ++x)
      for (int64_t y = y0; y <= y1; ++y)
        for (int64_t z = z0; z <= z1; ++z) visit(size_t((x * dims[1] + y) * dims[2] + z));
  };
  // Counting sort of (cell, face) entries; the order inside a cell does not matter.
  Buffer<uint32_t> start = filled_buffer(ncells + 1, 0u);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nf, 8192), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t f = range.begin(); f != range.end(); ++f)
      if (!skip[f]) for_cells(f, [&](size_t c) { __atomic_fetch_add(&start[c + 1], 1u, __ATOMIC_RELAXED); });
  });
  for (size_t c = 0; c < ncells; ++c) start[c + 1] += start[c];
  Buffer<uint32_t> entries(start[ncells]);
  {
    Buffer<uint32_t> cursor = copied_buffer(start.data(), ncells);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, nf, 8192), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t f = range.begin(); f != range.end(); ++f)
        if (!skip[f])
          for_cells(f, [&](size_t c) { entries[__atomic_fetch_add(&cursor[c], 1u, __ATOMIC_RELAXED)] = uint32_t(f); });
    });
  }
  progress.advance(4);
  std::atomic<bool> hit{false};
  const size_t chunks = 12;
  // Each cell's faces are gathered once into a local list, so the pair loop reads nothing else.
  struct Local {
    FaceBox box;
    std::array<uint32_t, 3> v;
    uint32_t face;
    uint8_t graph_fans;  // bit k: v[k] has a graph fan
    uint8_t starts_here;  // bit k: the box starts in this cell's slice along axis k
  };
  tbb::parallel_for(size_t(0), chunks, [&](size_t chunk) {
    const size_t c0 = ncells * chunk / chunks, c1 = ncells * (chunk + 1) / chunks;
    tbb::parallel_for(tbb::blocked_range<size_t>(c0, c1, 1024), [&](const tbb::blocked_range<size_t>& range) {
      std::vector<Local> local;
      std::vector<uint32_t> candidates;
      for (size_t c = range.begin(); c != range.end() && !hit.load(std::memory_order_relaxed); ++c) {
        const uint32_t* list = entries.data() + start[c];
        const size_t n = start[c + 1] - start[c];
        if (n < 2) continue;
        const int64_t cz = int64_t(c) % dims[2], cy = (int64_t(c) / dims[2]) % dims[1], cx = int64_t(c) / (dims[1] * dims[2]);
        const int64_t here[3] = {cx, cy, cz};
        local.resize(n);
        for (size_t i = 0; i < n; ++i) {
          const uint32_t f = list[i];
          const auto& t = mesh.triangles[f];
          // The cell of the box's lowest corner; the overlap of two boxes starts in the larger of
          // theirs, and neither starts beyond this cell (both are listed in it), so the overlap starts
          // here exactly when, along every axis, one of the two starts here.
          uint8_t starts_here = 0;
          const FaceBox box = box_of(f);
          for (int k = 0; k < 3; ++k) starts_here |= uint8_t((cell_of(box.lo[k], k) == here[k]) << k);
          local[i] = {box, t, f, uint8_t(graph_fan[t[0]] | graph_fan[t[1]] << 1 | graph_fan[t[2]] << 2), starts_here};
        }
        // By the boxes' lower x, so each face meets only the run of faces that start before it ends.
        std::sort(local.begin(), local.end(), [](const Local& a, const Local& b) {
          return a.box.lo[0] != b.box.lo[0] ? a.box.lo[0] < b.box.lo[0] : a.face < b.face;
        });
        candidates.resize(n);
        for (size_t i = 0; i + 1 < n; ++i) {
          const Local& a = local[i];
          // The faces after a whose boxes meet a's and whose overlap starts in this cell, and that
          // share no vertex with a graph fan with a, listed without a branch per face (most fail one
          // of the tests, unpredictably): each is written and kept only when it passed.
          size_t kept = 0;
          for (size_t j = i + 1; j < n && local[j].box.lo[0] <= a.box.hi[0]; ++j) {
            const Local& b = local[j];
            const bool overlap = (a.box.lo[1] <= b.box.hi[1]) & (b.box.lo[1] <= a.box.hi[1]) &
                                 (a.box.lo[2] <= b.box.hi[2]) & (b.box.lo[2] <= a.box.hi[2]);
            bool in_graph_fan = false;
            for (int k = 0; k < 3; ++k)
              in_graph_fan |= bool(a.graph_fans >> k & 1) &
                              ((a.v[size_t(k)] == b.v[0]) | (a.v[size_t(k)] == b.v[1]) | (a.v[size_t(k)] == b.v[2]));
            candidates[kept] = uint32_t(j);
            kept += size_t(overlap & ((a.starts_here | b.starts_here) == 7) & !in_graph_fan);
          }
          for (size_t q = 0; q < kept; ++q)
            if (exact::faces_intersect(mesh.positions_mm.data(), a.v, local[candidates[q]].v)) {
              hit = true;
              return;
            }
        }
      }
    });
    progress.advance(1);
  });
  return hit;
}

}  // namespace

std::vector<uint32_t> component_depths(const TriMesh& mesh) {
  std::vector<MeshComponent> components = mesh_components(mesh);
  std::vector<uint32_t> component_of(mesh.positions_mm.size(), 0);
  for (size_t c = 0; c < components.size(); ++c)
    for (uint32_t f : components[c].triangles)
      for (uint32_t v : mesh.triangles[f]) component_of[v] = uint32_t(c);
  return nesting_depths(mesh, component_of, components.size());
}

bool MeshCheckReport::valid() const {
  return triangles > 0 && non_finite_vertices == 0 && bad_indices == 0 && degenerate_faces == 0 && closed() &&
         manifold() && outward() && self_intersections_checked && !self_intersecting && volume_mm3 > 0;
}

std::vector<std::string> MeshCheckReport::problems() const {
  std::vector<std::string> out;
  auto count = [](uint64_t n, const char* what) { return std::to_string(n) + " " + what; };
  if (triangles == 0) out.push_back("the mesh has no triangles");
  if (non_finite_vertices) out.push_back(count(non_finite_vertices, "vertices have non-finite coordinates (NaN or infinity)"));
  if (bad_indices) out.push_back(count(bad_indices, "triangle corners refer to vertices that do not exist"));
  if (degenerate_faces) out.push_back(count(degenerate_faces, "degenerate faces (repeated or collinear corners)"));
  if (boundary_edges) out.push_back(count(boundary_edges, "boundary edges: the mesh is not closed"));
  if (non_manifold_edges) out.push_back(count(non_manifold_edges, "edges shared by more than two faces"));
  if (misoriented_edges) out.push_back(count(misoriented_edges, "edges whose faces are oriented inconsistently"));
  if (non_manifold_vertices) out.push_back(count(non_manifold_vertices, "non-manifold vertices (faces meeting only at a point)"));
  if (!vertex_manifold_checked && triangles > 0 && !boundary_edges && !non_manifold_edges && !misoriented_edges)
    out.push_back("vertex manifoldness not checked");
  if (inward_components) out.push_back(count(inward_components, "components are oriented inward"));
  if (self_intersecting) out.push_back("the mesh intersects itself");
  else if (!self_intersections_checked && triangles > 0)
    out.push_back("self-intersections not checked (the mesh is not a closed oriented manifold)");
  if (triangles > 0 && volume_mm3 <= 0) out.push_back("the enclosed volume is not positive");
  return out;
}

MeshCheckReport check_mesh(const TriMesh& mesh, const CheckOptions& options) {
  MeshCheckReport r;
  const size_t nv = mesh.positions_mm.size(), nf = mesh.triangles.size();
  r.vertices = nv;
  r.triangles = nf;
  struct Finite {
    uint64_t non_finite = 0;
    Box3 box;
  };
  const Finite finite = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, nv, 16384), Finite(),
      [&](const tbb::blocked_range<size_t>& range, Finite f) {
        for (size_t v = range.begin(); v != range.end(); ++v) {
          const Vec3d& p = mesh.positions_mm[v];
          if (!is_finite(p)) ++f.non_finite;
          else f.box.expand(p);
        }
        return f;
      },
      [](Finite a, const Finite& b) {
        a.non_finite += b.non_finite;
        if (!b.box.empty()) {
          a.box.expand(b.box.min);
          a.box.expand(b.box.max);
        }
        return a;
      });
  r.non_finite_vertices = finite.non_finite;
  r.bounding_box = finite.box;
  r.bad_indices = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, nf, 16384), uint64_t{0},
      [&](const tbb::blocked_range<size_t>& range, uint64_t n) {
        for (size_t f = range.begin(); f != range.end(); ++f)
          for (uint32_t v : mesh.triangles[f]) n += v >= nv;
        return n;
      },
      std::plus<uint64_t>());
  if (nf == 0 || r.bad_indices || r.non_finite_vertices) return r;

  Progress progress("check", 4 + 16);
  // Degenerate faces: a repeated corner or three collinear corners (exact predicate).
  std::vector<uint8_t> degenerate(nf, 0);
  r.degenerate_faces = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, nf, 4096), uint64_t{0},
      [&](const tbb::blocked_range<size_t>& range, uint64_t n) {
        for (size_t f = range.begin(); f != range.end(); ++f) {
          if (degenerate_face(mesh, mesh.triangles[f])) {
            degenerate[f] = 1;
            ++n;
          }
        }
        return n;
      },
      std::plus<uint64_t>());
  progress.advance();
  // Edges: every undirected edge must have exactly two faces running it in opposite directions.
  const VertexCorners corners = vertex_corners(mesh);
  const EdgeTopology edges = edge_topology(mesh, corners);
  r.edges = edges.edges;
  r.boundary_edges = edges.boundary_edges;
  r.non_manifold_edges = edges.non_manifold_edges;
  r.misoriented_edges = edges.misoriented_edges;
  progress.advance();
  // Vertex manifoldness: the faces around each vertex form one fan, closed around it.
  const bool edges_clean = edges.clean();
  if (edges_clean) {
    const std::vector<uint32_t> fans = vertex_fans(mesh, edges, corners);
    r.non_manifold_vertices = uint64_t(std::count_if(fans.begin(), fans.end(), [](uint32_t n) { return n > 1; }));
    r.vertex_manifold_checked = true;
  }
  progress.advance();
  // Components, genus, volume and area.
  const VertexComponents components = vertex_components(mesh);
  const size_t nc = components.count;
  r.components = nc;
  const std::vector<int64_t> euler = euler_characteristics(mesh, edges, components);
  std::vector<long double> volume6(nc, 0);
  const Vec3d center = (r.bounding_box.min + r.bounding_box.max) * 0.5;
  long double area2 = 0;
  {
    // In fixed blocks of triangles, each with its own sums per component (when that is not too
    // many), added up in block order: the same figures for any number of threads.
    const size_t blocks = nf / 65536 + 1;
    const bool per_block = blocks > 1 && double(blocks) * double(nc) <= 16e6;
    auto add = [&](size_t f0, size_t f1, std::vector<long double>& v6, long double& a2) {
      for (size_t f = f0; f < f1; ++f) {
        const auto& t = mesh.triangles[f];
        const Vec3d a = mesh.positions_mm[t[0]] - center, b = mesh.positions_mm[t[1]] - center,
                    d = mesh.positions_mm[t[2]] - center;
        v6[components.of_vertex[t[0]]] += dot(a, cross(b, d));
        a2 += norm(cross(b - a, d - a));
      }
    };
    if (!per_block) {
      add(0, nf, volume6, area2);
    } else {
      std::vector<std::vector<long double>> block_volume6(blocks);
      std::vector<long double> block_area2(blocks, 0);
      tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
        block_volume6[b].assign(nc, 0);
        add(nf * b / blocks, nf * (b + 1) / blocks, block_volume6[b], block_area2[b]);
      });
      for (size_t b = 0; b < blocks; ++b) {
        for (size_t c = 0; c < nc; ++c) volume6[c] += block_volume6[b][c];
        area2 += block_area2[b];
      }
    }
  }
  long double total6 = 0;
  for (size_t c = 0; c < nc; ++c) {
    total6 += volume6[c];
    r.genus += (2 - euler[c]) / 2;
  }
  r.volume_mm3 = double(total6 / 6.0L);
  r.area_mm2 = double(area2 / 2.0L);

  // Outward orientation: a component nested inside an odd number of others bounds a cavity and
  // must have negative volume; every other component positive.
  if (edges_clean) {
    r.orientation_checked = true;
    std::vector<uint32_t> depth = nesting_depths(mesh, components.of_vertex, nc);
    for (size_t c = 0; c < nc; ++c)
      if ((volume6[c] > 0) != (depth[c] % 2 == 0)) ++r.inward_components;
  }
  progress.advance();
  if (options.self_intersections && edges_clean && r.non_manifold_vertices == 0) {
    r.self_intersecting = self_intersects(mesh, edges, corners, degenerate, progress);
    r.self_intersections_checked = true;
  }
  return r;
}


// The mesh comes in chunks W_0, W_1, ... and is checked two chunks at a time (a window), so every
// pair of triangles that can touch is in some window: a chunk lies above (in z) every triangle two
// chunks before it, which is tested. A vertex, an edge or a face is counted in the first window
// holding it (whose first chunk has one of its faces, or the last window); an edge open in a
// window is open in the mesh when the window after it (holding its face's other neighbours) finds it
// open too; components are joined across windows through the vertices of their shared chunk; a
// component's nesting comes from a ray from one of its faces in the window that holds every
// triangle crossing the ray's plane.
struct ChunkedCheck::Impl {
  CheckOptions options;
  MeshCheckReport r;
  std::vector<std::array<Vec3d, 3>> previous;  // the last chunk given
  size_t chunks = 0;
  double z_max_before = -HUGE_VAL;  // the top of every chunk before `previous`
  double z_max_previous = -HUGE_VAL;
  bool done = false;
  bool separated = true;            // every chunk above the one two before it
  bool fans_checked = true, intersections_checked = true;
  using Edge = std::array<float, 6>;
  std::vector<Edge> open_ahead;     // open edges of the last window with a face in its second chunk, sorted
  // The vertices of `previous` (as the last window numbered them) and the component node of each.
  std::vector<std::array<float, 3>> seam_points;
  std::vector<uint32_t> seam_nodes;
  std::vector<uint8_t> seam_counted;                    // counted in the last window
  std::vector<std::pair<uint32_t, uint32_t>> seam_match;  // (vertex here, its node there)
  // Component nodes (one per window component), joined across windows.
  std::vector<uint32_t> parent;
  std::vector<long double> volume6;
  std::vector<int64_t> euler;
  struct Probe {
    uint32_t node;
  };
  std::vector<Probe> probes;
  std::vector<std::pair<uint32_t, uint32_t>> crossings;  // (probe, node) crossed an odd number of times
  Vec3d origin;
  bool has_origin = false;
  long double area2 = 0;

  uint32_t find(uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }

  static Edge edge_of(const TriMesh& m, uint32_t h) {
    const Vec3d &a = m.positions_mm[half_edge_from(m, h)], &b = m.positions_mm[half_edge_to(m, h)];
    return {float(a.x), float(a.y), float(a.z), float(b.x), float(b.y), float(b.z)};
  }

  // The window of chunks a (the first) and b (possibly empty); `last`: no chunk follows b.
  void window(const std::vector<std::array<Vec3d, 3>>& a, const std::vector<std::array<Vec3d, 3>>& b, bool first,
              bool last) {
    const size_t na = a.size(), nf = na + b.size();
    std::vector<std::array<float, 3>> points;
    points.reserve(3 * nf);
    uint64_t non_finite = 0;
    for (size_t f = 0; f < nf; ++f)
      for (const Vec3d& p : f < na ? a[f] : b[f - na]) {
        if (!is_finite(p)) ++non_finite;
        points.push_back({float(p.x), float(p.y), float(p.z)});
      }
    if (non_finite) {
      r.non_finite_vertices += non_finite;
      fans_checked = intersections_checked = false;
      return;
    }
    std::vector<std::array<float, 3>> unique_points = points;
    tbb::parallel_sort(unique_points.begin(), unique_points.end());
    unique_points.erase(std::unique(unique_points.begin(), unique_points.end()), unique_points.end());
    TriMesh m;
    m.positions_mm.resize(unique_points.size());
    for (size_t v = 0; v < unique_points.size(); ++v)
      m.positions_mm[v] = {unique_points[v][0], unique_points[v][1], unique_points[v][2]};
    m.triangles.resize(nf);
    tbb::parallel_for(size_t(0), nf, [&](size_t f) {
      for (int k = 0; k < 3; ++k)
        m.triangles[f][size_t(k)] = uint32_t(std::lower_bound(unique_points.begin(), unique_points.end(), points[3 * f + size_t(k)]) -
                                             unique_points.begin());
    });
    std::vector<std::array<float, 3>>().swap(points);
    const size_t nv = m.positions_mm.size();
    auto counted_face = [&](size_t f) { return f < na || last; };
    // Per vertex: 1 a face in the first chunk, 2 a face in the second.
    std::vector<uint8_t> in_chunk(nv, 0);
    for (size_t f = 0; f < nf; ++f)
      for (uint32_t v : m.triangles[f]) in_chunk[v] |= f < na ? 1 : 2;
    // A first-chunk vertex the last window had a first-chunk face at was counted there.
    std::vector<uint8_t> seen_before(nv, 0);
    for (uint32_t v = 0; v < nv; ++v) {
      if (!(in_chunk[v] & 1)) continue;
      const std::array<float, 3> key{float(m.positions_mm[v].x), float(m.positions_mm[v].y), float(m.positions_mm[v].z)};
      auto it = std::lower_bound(seam_points.begin(), seam_points.end(), key);
      if (it != seam_points.end() && *it == key) {
        const size_t at = size_t(it - seam_points.begin());
        seen_before[v] = seam_counted[at];
        seam_match.push_back({v, seam_nodes[at]});
      }
    }
    auto counted_vertex = [&](uint32_t v) { return ((in_chunk[v] & 1) || last) && !seen_before[v]; };
    if (!has_origin && nv) {
      origin = m.positions_mm[0];
      has_origin = true;
    }
    // Faces.
    std::vector<uint8_t> degenerate(nf, 0);
    for (size_t f = 0; f < nf; ++f) {
      const auto& t = m.triangles[f];
      if (degenerate_face(m, t)) {
        degenerate[f] = 1;
        r.degenerate_faces += counted_face(f);
      }
      if (counted_face(f)) {
        ++r.triangles;
        for (uint32_t v : t) r.bounding_box.expand(m.positions_mm[v]);
      }
    }
    // Edges.
    const VertexCorners corners = vertex_corners(m);
    const EdgeTopology edges = edge_topology(m, corners);
    auto has_first_face = [&](uint32_t h) {
      const uint32_t u = half_edge_from(m, h), w = half_edge_to(m, h);
      for (uint64_t i = corners.offsets[u]; i < corners.offsets[u + 1]; ++i) {
        const uint32_t f = corners.corners[i] / 3;
        const auto& t = m.triangles[f];
        if ((t[0] == w || t[1] == w || t[2] == w) && counted_face(f)) return true;
      }
      return false;
    };
    for (uint32_t h : edges.non_manifold) r.non_manifold_edges += has_first_face(h);
    for (uint32_t h : edges.misoriented) r.misoriented_edges += has_first_face(h);
    std::vector<uint8_t> on_open(nv, 0);
    std::vector<Edge> ahead;
    for (uint32_t h : edges.boundary) {
      on_open[half_edge_from(m, h)] = on_open[half_edge_to(m, h)] = 1;
      if (h / 3 >= na) ahead.push_back(edge_of(m, h));
    }
    // An edge open here with its face in the first chunk was closed in the last window (and counted
    // there) unless that window found it open too.
    std::vector<uint8_t> counted_before(3 * nf, 0);
    for (uint32_t h : edges.boundary) {
      if (h / 3 >= na) continue;
      if (first || std::binary_search(open_ahead.begin(), open_ahead.end(), edge_of(m, h))) ++r.boundary_edges;
      else counted_before[h] = 1;
    }
    std::sort(ahead.begin(), ahead.end());
    if (last) {
      r.boundary_edges += ahead.size();
      ahead.clear();
    }
    open_ahead.swap(ahead);
    for (uint32_t h : edges.non_manifold) on_open[half_edge_from(m, h)] = on_open[half_edge_to(m, h)] = 1;
    for (uint32_t h : edges.misoriented) on_open[half_edge_from(m, h)] = on_open[half_edge_to(m, h)] = 1;
    // Vertices: fans where every face of the vertex is here.
    const bool edges_clean = edges.non_manifold_edges == 0 && edges.misoriented_edges == 0;
    uint64_t bad_fans = 0;
    if (edges_clean) {
      const std::vector<uint32_t> fans = vertex_fans(m, edges, corners);
      for (uint32_t v = 0; v < nv; ++v)
        if (!on_open[v] && fans[v] > 1) {
          ++bad_fans;
          r.non_manifold_vertices += counted_vertex(v);
        }
    } else {
      fans_checked = false;
    }
    // Components, joined to the last window's through the first chunk's vertices.
    const VertexComponents components = vertex_components(m);
    const uint32_t base = uint32_t(parent.size());
    for (uint32_t c = 0; c < components.count; ++c) parent.push_back(base + c);
    volume6.resize(parent.size(), 0);
    euler.resize(parent.size(), 0);
    for (uint32_t v = 0; v < nv; ++v) {
      if (!counted_vertex(v)) continue;
      ++r.vertices;
      ++euler[base + components.of_vertex[v]];
    }
    for (size_t h = 0; h < 3 * nf; ++h) {
      const size_t f = h / 3;
      if (!counted_face(f)) continue;
      const uint32_t g = edges.opposite[h];
      // Once per edge: at its half-edge here, or at the smaller of two here.
      if (g != kNoHalfEdge && counted_face(g / 3) && g < h) continue;
      if (counted_before[h]) continue;
      ++r.edges;
      --euler[base + components.of_vertex[half_edge_from(m, uint32_t(h))]];
    }
    for (size_t f = 0; f < nf; ++f) {
      if (!counted_face(f)) continue;
      const auto& t = m.triangles[f];
      const uint32_t c = base + components.of_vertex[t[0]];
      ++euler[c];
      const Vec3d p0 = m.positions_mm[t[0]] - origin, p1 = m.positions_mm[t[1]] - origin, p2 = m.positions_mm[t[2]] - origin;
      volume6[c] += dot(p0, cross(p1, p2));
      area2 += norm(cross(p1 - p0, p2 - p0));
    }
    for (const auto& [v, node] : seam_match) join(node, base + components.of_vertex[v]);
    seam_match.clear();
    seam_points.clear();
    seam_nodes.clear();
    seam_counted.clear();
    for (uint32_t v = 0; v < nv; ++v)  // sorted: the positions are
      if (in_chunk[v] & 2) {
        seam_points.push_back({float(m.positions_mm[v].x), float(m.positions_mm[v].y), float(m.positions_mm[v].z)});
        seam_nodes.push_back(base + components.of_vertex[v]);
        seam_counted.push_back(counted_vertex(v) ? 1 : 0);
      }
    // Probes: per component, its first face whose plane z = centroid only this window's
    // triangles cross (a first-chunk face above the chunk before, or a second-chunk face below
    // the first chunk's top; any second-chunk face in the last window).
    std::vector<Vec3d> probe;
    std::vector<uint32_t> own;
    std::vector<uint8_t> probed(components.count, 0);
    for (size_t f = 0; f < nf; ++f) {
      const auto& t = m.triangles[f];
      const uint32_t c = components.of_vertex[t[0]];
      if (probed[c]) continue;
      const Vec3d centroid = (m.positions_mm[t[0]] + m.positions_mm[t[1]] + m.positions_mm[t[2]]) / 3.0;
      const bool here = f < na ? (first || centroid.z > z_max_before) : (last || centroid.z <= z_max_previous);
      if (!here) continue;
      probed[c] = 1;
      probe.push_back(centroid);
      own.push_back(c);
    }
    const uint32_t probe_base = uint32_t(probes.size());
    for (uint32_t c : own) probes.push_back({base + c});
    if (!probe.empty())
      for (const auto& [q, c] : odd_crossings(m, components.of_vertex, probe, own)) crossings.push_back({probe_base + q, base + c});
    // Self-intersections among the window's faces.
    if (options.self_intersections && edges_clean && bad_fans == 0) {
      Progress progress("check", 4 + 16);
      r.self_intersecting = r.self_intersecting || self_intersects(m, edges, corners, degenerate, progress);
    } else {
      intersections_checked = false;
    }
  }
};

ChunkedCheck::ChunkedCheck(const CheckOptions& options) : impl_(std::make_unique<Impl>()) { impl_->options = options; }
ChunkedCheck::~ChunkedCheck() = default;

void ChunkedCheck::add(std::vector<std::array<Vec3d, 3>> chunk, bool last) {
  Impl& m = *impl_;
  if (m.done) throw InternalError("ChunkedCheck::add after the last chunk");
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (const auto& t : chunk)
    for (const Vec3d& p : t) {
      lo = std::min(lo, p.z);
      hi = std::max(hi, p.z);
    }
  if (m.chunks >= 2 && !chunk.empty() && !(lo > m.z_max_before)) m.separated = false;
  if (m.chunks == 0 && last) m.window(chunk, {}, true, true);
  if (m.chunks >= 1) m.window(m.previous, chunk, m.chunks == 1, last);
  ++m.chunks;
  m.z_max_before = std::max(m.z_max_before, m.z_max_previous);  // the top of every chunk but the last
  m.z_max_previous = hi;
  m.previous = std::move(chunk);
  m.done = last;
}

MeshCheckReport ChunkedCheck::finish() {
  Impl& m = *impl_;
  if (!m.done && m.chunks) throw InternalError("ChunkedCheck::finish before the last chunk");
  m.previous.clear();
  MeshCheckReport& r = m.r;
  // As check_mesh: vertices, orientation and intersections only on a closed surface with clean edges.
  const bool edges_clean = r.boundary_edges == 0 && r.non_manifold_edges == 0 && r.misoriented_edges == 0;
  r.vertex_manifold_checked = m.fans_checked && edges_clean;
  if (!r.vertex_manifold_checked) r.non_manifold_vertices = 0;
  r.orientation_checked = r.vertex_manifold_checked;
  r.self_intersections_checked =
      m.intersections_checked && m.separated && r.vertex_manifold_checked && r.non_manifold_vertices == 0;
  if (!r.self_intersections_checked) r.self_intersecting = false;
  const size_t nodes = m.parent.size();
  std::vector<long double> volume6(nodes, 0);
  std::vector<int64_t> euler(nodes, 0);
  for (uint32_t c = 0; c < nodes; ++c) {
    const uint32_t root = m.find(c);
    volume6[root] += m.volume6[c];
    euler[root] += m.euler[c];
  }
  long double total6 = 0;
  std::vector<uint32_t> probe_of(nodes, UINT32_MAX);
  for (uint32_t q = 0; q < m.probes.size(); ++q) {
    const uint32_t root = m.find(m.probes[q].node);
    if (probe_of[root] == UINT32_MAX) probe_of[root] = q;
  }
  std::vector<std::pair<uint32_t, uint32_t>> crossed;  // (probe, root crossed), one per odd crossing
  for (const auto& [q, node] : m.crossings) {
    // A window may hold a component in pieces joined only later (a cup's inner and outer walls): a
    // crossing with another piece of the probe's own component is no nesting.
    const uint32_t root = m.find(node), own = m.find(m.probes[q].node);
    if (probe_of[own] == q && root != own) crossed.push_back({q, root});
  }
  std::sort(crossed.begin(), crossed.end());
  std::vector<uint32_t> depth(m.probes.size(), 0);
  for (size_t i = 0; i < crossed.size();) {
    size_t j = i;
    while (j < crossed.size() && crossed[j] == crossed[i]) ++j;
    depth[crossed[i].first] += (j - i) % 2;
    i = j;
  }
  for (uint32_t c = 0; c < nodes; ++c) {
    if (m.find(c) != c) continue;
    ++r.components;
    total6 += volume6[c];
    r.genus += (2 - euler[c]) / 2;
    if (r.orientation_checked && probe_of[c] != UINT32_MAX && (volume6[c] > 0) != (depth[probe_of[c]] % 2 == 0))
      ++r.inward_components;
  }
  r.volume_mm3 = double(total6 / 6.0L);
  r.area_mm2 = double(m.area2 / 2.0L);
  return r;
}

}  // namespace lacuna
