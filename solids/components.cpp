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
  std::vector<uint32_t> index(mesh.positions_mm.size(), UINT32_MAX);
  TriMesh kept;
  for (const auto& t : mesh.triangles) {
    if (drop[components.of_vertex[t[0]]]) continue;
    std::array<uint32_t, 3> out{};
    for (int k = 0; k < 3; ++k) {
      uint32_t& i = index[t[size_t(k)]];
      if (i == UINT32_MAX) {
        i = uint32_t(kept.positions_mm.size());
        kept.positions_mm.push_back(mesh.positions_mm[t[size_t(k)]]);
      }
      out[size_t(k)] = i;
    }
    kept.triangles.push_back(out);
  }
  mesh = std::move(kept);
  return removed;
}

}  // namespace lacuna
