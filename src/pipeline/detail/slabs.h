// How a streamed run cuts an object into slabs along z (not part of the pipeline's public API):
// `lacuna slice` in leaves of 8 voxels, streamed meshes in the surface's blocks of 32.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pipeline/evaluate.h"
#include "solids/voxelize.h"
#include "util/system.h"

namespace lacuna {
namespace detail {

struct SlabLayout {
  double halo = 0;    // each slab is evaluated this much deeper below and above (whole leaves)
  double bottom = 0;  // the first slab's own part starts here (a multiple of the unit)
  double top = 0;     // the last slab's own part reaches this
  double whole = 0;   // top - bottom rounded up to whole units
  double height = 0;  // of each slab (whole units); 0: the whole part at once
  // Slab i's own part is [cuts[i], cuts[i + 1]), cuts[i] = bottom + i height (each computed, not
  // summed, so that neighbours and every estimate agree to the bit), up to the first cut at or above top.
  std::vector<double> cuts() const;
  // The slabs the cuts make, each grown by the halo below and above.
  std::vector<ZSlab> slabs() const;
};

// The slabs of `extent` (its object's voxel size h, band in mm): `slab_mm` high rounded up to whole
// `unit`s (a multiple of 8 voxels), or, when 0, the whole part if the estimate fits the budget and
// otherwise the highest slabs that do. Each slab's halo reaches as deep as the object's operations
// look around, a band and two voxels more. Throws ResourceLimit naming `what` when even one unit
// does not fit.
SlabLayout slab_layout(const MemoryEstimator& estimator, const ObjectExtent& extent, double h, double band, double unit,
                       double slab_mm, uint64_t budget, const std::string& what);

// A timer's stages, each started once per slab, added up by name in the order they first ran.
std::vector<std::pair<std::string, double>> stage_totals(const StageTimer& timer);

}  // namespace detail
}  // namespace lacuna
