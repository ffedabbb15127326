#include "solids/components.h"

#include "solids/mesh_topology.h"

namespace lacuna {

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

namespace {

// Removes the components `drop_it` picks and the vertices left unused; returns how many.
template <class Pick>
size_t drop_components(TriMesh& mesh, Pick&& drop_it) {
  std::vector<char> drop(mesh.triangles.size(), 0);
  size_t removed = 0;
  for (const MeshComponent& c : mesh_components(mesh)) {
    if (!drop_it(c)) continue;
    ++removed;
    for (uint32_t f : c.triangles) drop[f] = 1;
  }
  if (removed == 0) return 0;
  std::vector<int64_t> index(mesh.positions_mm.size(), -1);
  TriMesh kept;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (drop[f]) continue;
    std::array<uint32_t, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[f][size_t(k)];
      if (index[v] < 0) {
        index[v] = int64_t(kept.positions_mm.size());
        kept.positions_mm.push_back(mesh.positions_mm[v]);
      }
      t[size_t(k)] = uint32_t(index[v]);
    }
    kept.triangles.push_back(t);
  }
  mesh = std::move(kept);
  return removed;
}

}  // namespace

size_t fill_small_cavities(TriMesh& mesh, double max_volume_mm3) {
  return drop_components(mesh, [&](const MeshComponent& c) {
    return c.signed_volume_mm3 < 0 && -c.signed_volume_mm3 < max_volume_mm3;
  });
}

size_t remove_small_specks(TriMesh& mesh, double max_volume_mm3) {
  return drop_components(mesh, [&](const MeshComponent& c) {
    return c.signed_volume_mm3 >= 0 && c.signed_volume_mm3 < max_volume_mm3;
  });
}

}  // namespace lacuna
