#include "solids/slice.h"

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "solids/vdb_internal.h"

namespace lacuna {

std::vector<float> sample_layer(const Volume& volume, double z_mm, const LayerGrid& grid) {
  std::vector<float> out(grid.pixels(), float(volume.band_mm()));
  if (volume.empty()) return out;
  const double inv_h = 1.0 / volume.voxel_size_mm();
  const float on_surface = float(1e-5 * volume.voxel_size_mm());
  tbb::parallel_for(tbb::blocked_range<int>(0, grid.height, 8), [&](const tbb::blocked_range<int>& rows) {
    openvdb::FloatGrid::ConstAccessor accessor = volume.impl().grid->getConstAccessor();
    for (int j = rows.begin(); j < rows.end(); ++j) {
      const double y = (grid.origin_mm.y + j * grid.pixel_y_mm()) * inv_h;
      float* row = out.data() + size_t(j) * size_t(grid.width);
      for (int i = 0; i < grid.width; ++i) {
        const openvdb::Vec3d index((grid.origin_mm.x + i * grid.pixel_mm) * inv_h, y, z_mm * inv_h);
        const float d = openvdb::tools::BoxSampler::sample(accessor, index);
        row[i] = std::abs(d) < on_surface ? -on_surface : d;
      }
    }
  });
  return out;
}

Box3 solid_box(const Volume& volume) {
  return solid_box(volume, -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
}

Box3 solid_box(const Volume& volume, double z_lo_mm, double z_hi_mm) {
  if (volume.empty()) return Box3{};
  const openvdb::FloatGrid& grid = *volume.impl().grid;
  const double h = volume.voxel_size_mm();
  using LeafRange = openvdb::tree::LeafManager<const openvdb::FloatTree>::LeafRange;
  openvdb::tree::LeafManager<const openvdb::FloatTree> leaves(grid.tree());
  return tbb::parallel_reduce(
      leaves.leafRange(), Box3{},
      [&](const LeafRange& range, Box3 box) {
        for (auto leaf = range.begin(); leaf; ++leaf) {
          for (auto v = leaf->cbeginValueOn(); v; ++v) {
            const float d = *v;
            if (!(d < 0)) continue;
            const openvdb::Coord c = v.getCoord();
            const Vec3d centre{c.x() * h, c.y() * h, c.z() * h};
            if (!(centre.z >= z_lo_mm && centre.z <= z_hi_mm)) continue;
            const double r = -double(d);
            box.expand(centre - Vec3d{r, r, r});
            box.expand(centre + Vec3d{r, r, r});
          }
        }
        return box;
      },
      [](Box3 a, const Box3& b) {
        a.expand(b);
        return a;
      });
}

}  // namespace lacuna
