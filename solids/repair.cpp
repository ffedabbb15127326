#include "solids/repair.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <unordered_map>

#include "errors.h"
#include "solids/components.h"
#include "solids/mesh_topology.h"
#include "solids/extract.h"
#include "solids/rasterize.h"

namespace lacuna {
namespace {

TriMesh weld(const TriMesh& in, double tolerance) {
  TriMesh out;
  std::vector<uint32_t> remap(in.positions_mm.size());
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
  const double cell = tolerance * 2;
  auto key = [](int64_t x, int64_t y, int64_t z) {
    return (uint64_t(x) * 73856093u) ^ (uint64_t(y) * 19349663u) ^ (uint64_t(z) * 83492791u);
  };
  for (size_t i = 0; i < in.positions_mm.size(); ++i) {
    const Vec3d& p = in.positions_mm[i];
    const int64_t cx = int64_t(std::floor(p.x / cell)), cy = int64_t(std::floor(p.y / cell)),
                  cz = int64_t(std::floor(p.z / cell));
    uint32_t found = UINT32_MAX;
    for (int64_t dx = -1; dx <= 1 && found == UINT32_MAX; ++dx)
      for (int64_t dy = -1; dy <= 1 && found == UINT32_MAX; ++dy)
        for (int64_t dz = -1; dz <= 1 && found == UINT32_MAX; ++dz) {
          auto it = cells.find(key(cx + dx, cy + dy, cz + dz));
          if (it == cells.end()) continue;
          for (uint32_t j : it->second)
            if (norm(out.positions_mm[j] - p) <= tolerance) {
              found = j;
              break;
            }
        }
    if (found == UINT32_MAX) {
      found = uint32_t(out.positions_mm.size());
      out.positions_mm.push_back(p);
      cells[key(cx, cy, cz)].push_back(found);
    }
    remap[i] = found;
  }
  std::set<std::array<uint32_t, 3>> seen;
  for (const auto& t : in.triangles) {
    std::array<uint32_t, 3> r{remap[t[0]], remap[t[1]], remap[t[2]]};
    if (r[0] == r[1] || r[1] == r[2] || r[0] == r[2]) continue;
    std::array<uint32_t, 3> sorted = r;
    std::sort(sorted.begin(), sorted.end());
    if (!seen.insert(sorted).second) continue;  // the same face twice
    out.triangles.push_back(r);
  }
  return out;
}

// Consistent orientation by walking across edges shared by two faces, then every component
// turned to enclose a positive volume.
TriMesh reorient(const TriMesh& in) {
  TriMesh out = in;
  // The face across each edge of each face, from the input (flips keep a face's edges).
  const EdgeTopology edges = edge_topology(in, true);
  auto runs = [](const std::array<uint32_t, 3>& t, uint32_t a, uint32_t b) {
    for (int k = 0; k < 3; ++k)
      if (t[size_t(k)] == a && t[size_t((k + 1) % 3)] == b) return true;
    return false;
  };
  std::vector<int8_t> done(in.triangles.size(), 0);
  for (uint32_t seed = 0; seed < out.triangles.size(); ++seed) {
    if (done[seed]) continue;
    std::vector<uint32_t> stack{seed};
    done[seed] = 1;
    while (!stack.empty()) {
      uint32_t f = stack.back();
      stack.pop_back();
      for (uint32_t k = 0; k < 3; ++k) {
        const uint32_t across = edges.partner[3 * f + k];
        if (across == kNoHalfEdge) continue;  // boundary or non-manifold: no neighbour to agree with
        const uint32_t g = across / 3;
        if (done[g]) continue;
        // The shared edge as face f runs it now.
        const uint32_t a0 = in.triangles[f][k], b0 = in.triangles[f][(k + 1) % 3];
        const uint32_t a = runs(out.triangles[f], a0, b0) ? a0 : b0, b = a == a0 ? b0 : a0;
        // The neighbour must run the shared edge the other way.
        if (runs(out.triangles[g], a, b)) std::swap(out.triangles[g][1], out.triangles[g][2]);
        done[g] = 1;
        stack.push_back(g);
      }
    }
  }
  for (const MeshComponent& c : mesh_components(out))
    if (c.signed_volume_mm3 < 0)
      for (uint32_t f : c.triangles) std::swap(out.triangles[f][1], out.triangles[f][2]);
  return out;
}

// Morphological closing of the surface's solid: thicken the surface by the gap width, keep what
// the outward shells of that thick surface enclose (the cracks are bridged, the inside filled),
// and take the thickening back.
TriMesh close_gaps(const TriMesh& in, double gap, double voxel) {
  GeometrySet thick;
  thick.surfaces.push_back(ThickSurface{in, 2 * gap});
  TriMesh skin = extract_surface(rasterize_primitives(thick, VolumeOptions{voxel, 3.0}));
  std::vector<MeshComponent> components = mesh_components(skin);
  // Bridged gaps leave the thickened surface around a sealed inside (an inward shell); without
  // one the surface stayed open and there is nothing to fill.
  bool sealed = false;
  for (const MeshComponent& c : components) sealed = sealed || c.signed_volume_mm3 < 0;
  if (!sealed)
    throw InvalidInput("closing gaps of " + std::to_string(gap) + " mm does not seal the surface: an opening is wider");
  TriMesh outer;
  for (const MeshComponent& c : components) {
    if (c.signed_volume_mm3 <= 0) continue;  // the inner side of the thick skin
    std::unordered_map<uint32_t, uint32_t> index;
    for (uint32_t f : c.triangles) {
      std::array<uint32_t, 3> t{};
      for (int k = 0; k < 3; ++k) {
        uint32_t v = skin.triangles[f][size_t(k)];
        auto [it, fresh] = index.emplace(v, uint32_t(outer.positions_mm.size()));
        if (fresh) outer.positions_mm.push_back(skin.positions_mm[v]);
        t[size_t(k)] = it->second;
      }
      outer.triangles.push_back(t);
    }
  }
  if (outer.triangles.empty()) throw InvalidInput("closing the gaps left nothing; the surface is smaller than the gap width");
  return extract_surface(offset(mesh_to_volume(outer, VolumeOptions{voxel, 3.0}), -gap));
}

}  // namespace

TriMesh repair_mesh(const TriMesh& mesh, const RepairOptions& options, double voxel_size_mm) {
  TriMesh out = mesh;
  if (options.weld_mm > 0) out = weld(out, options.weld_mm);
  if (options.reorient) out = reorient(out);
  if (options.close_gaps_mm > 0) out = close_gaps(out, options.close_gaps_mm, voxel_size_mm);
  return out;
}

}  // namespace lacuna
