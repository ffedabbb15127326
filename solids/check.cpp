#include "solids/check.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "solids/components.h"
#include "solids/disjoint_sets.h"
#include "util/progress.h"

namespace lacuna {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

struct HalfEdge {
  uint64_t key;  // (min vertex << 32) | max vertex
  uint32_t id;   // 3 * face + corner; the half-edge runs from corner to corner + 1
  bool operator<(const HalfEdge& o) const { return key != o.key ? key < o.key : id < o.id; }
};

// Orientation of (a, b, p) in the (y, z) projection, exact, with p moved by the infinitesimal
// (eps, eps^2) when it lies on the line ab (simulation of simplicity): two triangles sharing an
// edge then never both contain p, and a ray through a vertex or along an edge is counted once.
int orient_yz(const Vec3d& a, const Vec3d& b, const Vec3d& p) {
  CGAL::Orientation o = CGAL::orientation(Kernel::Point_2(a.y, a.z), Kernel::Point_2(b.y, b.z), Kernel::Point_2(p.y, p.z));
  if (o != CGAL::COLLINEAR) return o == CGAL::LEFT_TURN ? 1 : -1;
  if (b.z != a.z) return b.z > a.z ? -1 : 1;
  return b.y > a.y ? 1 : (b.y < a.y ? -1 : 0);
}

// Whether the ray from p along +x crosses triangle abc (exact predicates).
bool ray_crosses(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d& p) {
  CGAL::Orientation projected =
      CGAL::orientation(Kernel::Point_2(a.y, a.z), Kernel::Point_2(b.y, b.z), Kernel::Point_2(c.y, c.z));
  if (projected == CGAL::COLLINEAR) return false;  // parallel to the ray
  int s = projected == CGAL::LEFT_TURN ? 1 : -1;
  if (orient_yz(a, b, p) != s || orient_yz(b, c, p) != s || orient_yz(c, a, p) != s) return false;
  CGAL::Orientation side = CGAL::orientation(Point(a.x, a.y, a.z), Point(b.x, b.y, b.z), Point(c.x, c.y, c.z),
                                             Point(p.x, p.y, p.z));
  if (side == CGAL::COPLANAR) return false;
  // The plane meets the ray ahead of p when p lies on the side the +x direction leaves.
  return (side == CGAL::POSITIVE ? 1 : -1) * s < 0;
}

// For every component, how many other components enclose it: the parity of the crossings of a
// ray from one of its points along +x with each other component. Triangles are matched to the
// probes through a grid over (y, z), so the cost is one pass over the triangles.
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
  std::vector<std::vector<uint32_t>> crossed(nc);  // components whose surface each probe's ray crosses
  for (const auto& t : mesh.triangles) {
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
          if (q != owner && probe[q].x <= std::max({a.x, b.x, c.x}) && ray_crosses(a, b, c, probe[q]))
            crossed[q].push_back(owner);
      }
  }
  for (size_t q = 0; q < nc; ++q) {
    std::sort(crossed[q].begin(), crossed[q].end());
    for (size_t i = 0; i < crossed[q].size();) {
      size_t j = i;
      while (j < crossed[q].size() && crossed[q][j] == crossed[q][i]) ++j;
      depth[q] += (j - i) % 2;
      i = j;
    }
  }
  return depth;
}

// CGAL's test run on slabs of the mesh in parallel: faces sorted along the longest axis, cut
// into slabs, every face handed to each slab its box overlaps, so every pair of faces whose boxes
// meet is tested in some slab. CGAL's own parallel mode shuffles the boxes and ran no faster than
// one thread here.
bool self_intersects(const TriMesh& mesh, const Box3& box, bool& built, Progress& progress) {
  SurfaceMesh sm;
  sm.reserve(SurfaceMesh::size_type(mesh.positions_mm.size()), SurfaceMesh::size_type(mesh.triangles.size() * 3 / 2),
             SurfaceMesh::size_type(mesh.triangles.size()));
  for (const Vec3d& p : mesh.positions_mm) sm.add_vertex(Point(p.x, p.y, p.z));
  built = true;
  for (const auto& t : mesh.triangles) {
    auto f = sm.add_face(SurfaceMesh::Vertex_index(t[0]), SurfaceMesh::Vertex_index(t[1]),
                         SurfaceMesh::Vertex_index(t[2]));
    if (f == SurfaceMesh::null_face()) {
      built = false;
      return false;
    }
  }
  const size_t nf = mesh.triangles.size();
  Vec3d extent = box.size();
  int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  struct Span {
    double lo, hi;
  };
  std::vector<Span> spans(nf);
  std::vector<double> centres(nf);
  for (size_t f = 0; f < nf; ++f) {
    const auto& t = mesh.triangles[f];
    double a = mesh.positions_mm[t[0]][axis], b = mesh.positions_mm[t[1]][axis], c = mesh.positions_mm[t[2]][axis];
    spans[f] = {std::min({a, b, c}), std::max({a, b, c})};
    centres[f] = (spans[f].lo + spans[f].hi) * 0.5;
  }
  const size_t slabs = std::clamp<size_t>(nf / 50000, 1, 64);
  std::vector<double> cuts;  // slab j is [cuts[j], cuts[j + 1]]
  {
    std::vector<double> sorted = centres;
    std::sort(sorted.begin(), sorted.end());
    cuts.push_back(-HUGE_VAL);
    for (size_t j = 1; j < slabs; ++j) cuts.push_back(sorted[j * nf / slabs]);
    cuts.push_back(HUGE_VAL);
  }
  std::vector<std::vector<SurfaceMesh::Face_index>> members(slabs);
  for (size_t f = 0; f < nf; ++f) {
    size_t first = size_t(std::upper_bound(cuts.begin(), cuts.end(), spans[f].lo) - cuts.begin()) - 1;
    for (size_t j = first; j < slabs && cuts[j] <= spans[f].hi; ++j)
      members[j].push_back(SurfaceMesh::Face_index(uint32_t(f)));
  }
  std::atomic<bool> hit{false};
  tbb::parallel_for(size_t(0), slabs, [&](size_t j) {
    if (hit) return;
    if (CGAL::Polygon_mesh_processing::does_self_intersect<CGAL::Sequential_tag>(members[j], sm)) hit = true;
    progress.advance(16 / slabs + (j < 16 % slabs ? 1 : 0));
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
  for (const Vec3d& p : mesh.positions_mm) {
    if (!is_finite(p)) ++r.non_finite_vertices;
    else r.bounding_box.expand(p);
  }
  std::vector<uint8_t> face_ok(nf, 1);
  for (size_t f = 0; f < nf; ++f) {
    const auto& t = mesh.triangles[f];
    for (uint32_t v : t)
      if (v >= nv) {
        ++r.bad_indices;
        face_ok[f] = 0;
      }
  }
  if (nf == 0 || r.bad_indices || r.non_finite_vertices) return r;

  Progress progress("check", 4 + 16);
  // Degenerate faces: a repeated corner or three collinear corners (exact predicate).
  r.degenerate_faces = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, nf, 4096), uint64_t{0},
      [&](const tbb::blocked_range<size_t>& range, uint64_t n) {
        for (size_t f = range.begin(); f != range.end(); ++f) {
          const auto& t = mesh.triangles[f];
          if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
            ++n;
            continue;
          }
          const Vec3d &a = mesh.positions_mm[t[0]], &b = mesh.positions_mm[t[1]], &c = mesh.positions_mm[t[2]];
          if (CGAL::collinear(Point(a.x, a.y, a.z), Point(b.x, b.y, b.z), Point(c.x, c.y, c.z))) ++n;
        }
        return n;
      },
      std::plus<uint64_t>());
  progress.advance();

  // Edges: every undirected edge must have exactly two faces running it in opposite directions.
  std::vector<HalfEdge> half_edges(3 * nf);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nf, 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t f = range.begin(); f != range.end(); ++f) {
      const auto& t = mesh.triangles[f];
      for (int k = 0; k < 3; ++k) {
        uint64_t a = t[k], b = t[(k + 1) % 3];
        half_edges[3 * f + k] = HalfEdge{(std::min(a, b) << 32) | std::max(a, b), uint32_t(3 * f + k)};
      }
    }
  });
  tbb::parallel_sort(half_edges.begin(), half_edges.end());
  std::vector<uint32_t> opposite(3 * nf, UINT32_MAX);
  auto tail = [&](uint32_t he) { return mesh.triangles[he / 3][he % 3]; };
  std::vector<uint64_t> edge_keys;
  edge_keys.reserve(3 * nf / 2);
  for (size_t i = 0; i < half_edges.size();) {
    size_t j = i;
    while (j < half_edges.size() && half_edges[j].key == half_edges[i].key) ++j;
    size_t n = j - i;
    uint64_t key = half_edges[i].key;
    if ((key >> 32) != (key & 0xffffffffu)) {  // edges of degenerate (repeated-corner) faces aside
      edge_keys.push_back(key);
      if (n == 1) {
        ++r.boundary_edges;
      } else if (n > 2) {
        ++r.non_manifold_edges;
      } else {
        uint32_t h0 = half_edges[i].id, h1 = half_edges[i + 1].id;
        if (tail(h0) == tail(h1)) {
          ++r.misoriented_edges;
        } else {
          opposite[h0] = h1;
          opposite[h1] = h0;
        }
      }
    }
    i = j;
  }
  r.edges = edge_keys.size();
  std::vector<HalfEdge>().swap(half_edges);
  progress.advance();

  // Vertex manifoldness: the faces around each vertex form one fan, closed around it.
  const bool edges_clean = r.boundary_edges == 0 && r.non_manifold_edges == 0 && r.misoriented_edges == 0;
  std::vector<uint32_t> degree(nv, 0), some_out(nv, UINT32_MAX);
  for (size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      uint32_t v = mesh.triangles[f][k];
      ++degree[v];
      if (some_out[v] == UINT32_MAX) some_out[v] = uint32_t(3 * f + k);
    }
  if (edges_clean) {
    r.non_manifold_vertices = tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, nv, 4096), uint64_t{0},
        [&](const tbb::blocked_range<size_t>& range, uint64_t n) {
          for (size_t v = range.begin(); v != range.end(); ++v) {
            if (degree[v] == 0) continue;
            uint32_t start = some_out[v], he = start, fan = 0;
            do {
              uint32_t prev = 3 * (he / 3) + (he % 3 + 2) % 3;  // ends at v
              he = opposite[prev];                           // starts at v in the next face
              ++fan;
            } while (he != start && he != UINT32_MAX && fan <= degree[v]);
            if (fan != degree[v]) ++n;
          }
          return n;
        },
        std::plus<uint64_t>());
    r.vertex_manifold_checked = true;
  }
  progress.advance();

  // Components, genus, volume and area.
  DisjointSets sets(nv);
  for (const auto& t : mesh.triangles) {
    sets.join(t[0], t[1]);
    sets.join(t[1], t[2]);
  }
  std::vector<uint32_t> component_of(nv, UINT32_MAX);
  std::vector<uint32_t> root_component(nv, UINT32_MAX);
  for (size_t v = 0; v < nv; ++v) {
    if (degree[v] == 0) continue;
    uint32_t root = sets.find(uint32_t(v));
    if (root_component[root] == UINT32_MAX) root_component[root] = uint32_t(r.components++);
    component_of[v] = root_component[root];
  }
  const size_t nc = r.components;
  std::vector<int64_t> euler(nc, 0);
  std::vector<long double> volume6(nc, 0);
  for (size_t v = 0; v < nv; ++v)
    if (component_of[v] != UINT32_MAX) ++euler[component_of[v]];
  for (uint64_t key : edge_keys) --euler[component_of[key >> 32]];
  const Vec3d center = (r.bounding_box.min + r.bounding_box.max) * 0.5;
  long double area2 = 0;
  for (size_t f = 0; f < nf; ++f) {
    const auto& t = mesh.triangles[f];
    uint32_t c = component_of[t[0]];
    ++euler[c];
    Vec3d a = mesh.positions_mm[t[0]] - center, b = mesh.positions_mm[t[1]] - center,
          d = mesh.positions_mm[t[2]] - center;
    volume6[c] += dot(a, cross(b, d));
    area2 += norm(cross(b - a, d - a));
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
    std::vector<uint32_t> depth = nesting_depths(mesh, component_of, nc);
    for (size_t c = 0; c < nc; ++c)
      if ((volume6[c] > 0) != (depth[c] % 2 == 0)) ++r.inward_components;
  }
  progress.advance();

  if (options.self_intersections && edges_clean && r.non_manifold_vertices == 0) {
    bool built = false;
    bool hit = self_intersects(mesh, r.bounding_box, built, progress);
    r.self_intersections_checked = built;
    r.self_intersecting = built && hit;
  }
  return r;
}

}  // namespace lacuna
