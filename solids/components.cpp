#include "solids/components.h"

#include "solids/mesh_topology.h"

namespace lacuna {
namespace {

// The mesh without the triangles flagged in `drop` and the vertices left unused (the others keep their
// order).
void drop_triangles(TriMesh& mesh, const std::vector<uint8_t>& drop) {
  std::vector<uint32_t> index(mesh.positions_mm.size(), UINT32_MAX);
  TriMesh kept;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (drop[f]) continue;
    std::array<uint32_t, 3> out{};
    for (int k = 0; k < 3; ++k) {
      uint32_t& i = index[mesh.triangles[f][size_t(k)]];
      if (i == UINT32_MAX) {
        i = uint32_t(kept.positions_mm.size());
        kept.positions_mm.push_back(mesh.positions_mm[mesh.triangles[f][size_t(k)]]);
      }
      out[size_t(k)] = i;
    }
    kept.triangles.push_back(out);
  }
  mesh = std::move(kept);
}

}  // namespace

std::vector<MeshComponent> mesh_components(const TriMesh& m) {
  const VertexComponents components = vertex_components(m);
  std::vector<int> index(components.count, -1);  // by vertex component: the place in the output
  std::vector<MeshComponent> out;
  std::vector<Vec3d> moment;  // sum of det * (a + b + c), for the volume centroid
  for (uint32_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    const uint32_t root = components.of_vertex[t[0]];
    if (index[root] < 0) {
      index[root] = int(out.size());
      out.emplace_back();
      moment.emplace_back();
    }
    MeshComponent& c = out[size_t(index[root])];
    const Vec3d &a = m.positions_mm[t[0]], &b = m.positions_mm[t[1]], &d = m.positions_mm[t[2]];
    c.triangles.push_back(f);
    const double det = dot(a, cross(b, d));
    c.signed_volume_mm3 += det / 6.0;
    moment[size_t(index[root])] += (a + b + d) * det;
    c.area_mm2 += 0.5 * norm(cross(b - a, d - a));
    c.box.expand(a);
    c.box.expand(b);
    c.box.expand(d);
  }
  for (size_t i = 0; i < out.size(); ++i) {
    MeshComponent& c = out[i];
    if (c.signed_volume_mm3 != 0) {
      c.centroid_mm = moment[i] / (24.0 * c.signed_volume_mm3);
    } else {
      c.centroid_mm = (c.box.min + c.box.max) * 0.5;
    }
  }
  return out;
}

SmallShells remove_small_shells(TriMesh& mesh, double max_volume_mm3) {
  SmallShells removed;
  const VertexComponents components = vertex_components(mesh);
  const size_t nc = components.count;
  // Six times each shell's volume, from a point of its own (its first vertex) to keep the digits.
  std::vector<double> volume6(nc, 0.0);
  std::vector<uint32_t> anchor(nc, UINT32_MAX);
  for (const auto& t : mesh.triangles) {
    const uint32_t c = components.of_vertex[t[0]];
    if (anchor[c] == UINT32_MAX) anchor[c] = t[0];
    const Vec3d& o = mesh.positions_mm[anchor[c]];
    volume6[c] += dot(mesh.positions_mm[t[0]] - o, cross(mesh.positions_mm[t[1]] - o, mesh.positions_mm[t[2]] - o));
  }
  std::vector<uint8_t> drop(nc, 0);
  for (size_t c = 0; c < nc; ++c) {
    const double v = volume6[c] / 6;
    if (v < 0 && -v < max_volume_mm3) {
      drop[c] = 1;
      ++removed.cavities;
    } else if (v >= 0 && v < max_volume_mm3) {
      drop[c] = 1;
      ++removed.specks;
    }
  }
  if (removed.cavities + removed.specks == 0) return removed;
  std::vector<uint8_t> drop_triangle(mesh.triangles.size(), 0);
  for (size_t f = 0; f < mesh.triangles.size(); ++f) drop_triangle[f] = drop[components.of_vertex[mesh.triangles[f][0]]];
  drop_triangles(mesh, drop_triangle);
  return removed;
}

std::vector<MeshComponent> loose_pieces(const TriMesh& mesh, double max_volume_mm3) {
  std::vector<MeshComponent> all = mesh_components(mesh), out;
  auto inside = [](const Box3& inner, const Box3& outer) {
    return inner.min.x >= outer.min.x && inner.min.y >= outer.min.y && inner.min.z >= outer.min.z &&
           inner.max.x <= outer.max.x && inner.max.y <= outer.max.y && inner.max.z <= outer.max.z;
  };
  for (size_t c = 0; c < all.size(); ++c) {
    if (!(all[c].signed_volume_mm3 > 0 && all[c].signed_volume_mm3 < max_volume_mm3)) continue;
    bool holds = false;
    for (size_t o = 0; o < all.size() && !holds; ++o) holds = o != c && inside(all[o].box, all[c].box);
    if (!holds) out.push_back(std::move(all[c]));
  }
  return out;
}

void remove_components(TriMesh& mesh, const std::vector<MeshComponent>& components) {
  if (components.empty()) return;
  std::vector<uint8_t> drop(mesh.triangles.size(), 0);
  for (const MeshComponent& c : components)
    for (uint32_t t : c.triangles) drop[t] = 1;
  drop_triangles(mesh, drop);
}

}  // namespace lacuna
