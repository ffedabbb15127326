#include "pipeline/detail/memory.h"

#include <cmath>
#include <cstdio>

#include "errors.h"
#include "solids/budget.h"
#include "util/system.h"

namespace lacuna {
namespace detail {

std::string fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, v);
  return text;
}

std::string refusal(const std::string& what, uint64_t need, uint64_t budget, const VolumeOptions& vopt) {
  const double scale = std::sqrt(double(need) / double(budget)) * 1.05;
  const double fits = vopt.voxel_size_mm * scale;
  const std::string head = what + " needs about " + format_bytes(need) + ", more than the budget of " +
                           format_bytes(budget) + " (--max-memory); ";
  if (!(fits <= kMaxVoxelSizeMm)) return head + "no voxel size would make it fit (now " + fixed(vopt.voxel_size_mm, 4) + " mm)";
  return head + "a voxel size of " + fixed(fits, 3) + " mm or larger would fit (now " + fixed(vopt.voxel_size_mm, 4) + " mm)";
}

void require_mesh_memory(const Volume& v, uint64_t budget, const std::string& what, const VolumeOptions& vopt,
                         double simplify_mm) {
  const double mesh = double(estimate_from_voxels(v.active_voxel_count(), vopt).mesh_bytes) *
                      compact_mesh_share(simplify_mm, vopt.voxel_size_mm);
  uint64_t need = uint64_t(mesh) + current_memory_bytes();
  if (need > budget) throw ResourceLimit(refusal(what, need, budget, vopt));
}

void require_surface_memory(const Volume& v, uint64_t budget, const std::string& what, const VolumeOptions& vopt) {
  const uint64_t need = estimate_from_voxels(v.active_voxel_count(), vopt).surface_bytes + current_memory_bytes();
  if (need > budget) throw ResourceLimit(refusal(what, need, budget, vopt));
}

}  // namespace detail
}  // namespace lacuna
