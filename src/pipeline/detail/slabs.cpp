#include "pipeline/detail/slabs.h"

#include <algorithm>
#include <cmath>

#include "errors.h"
#include "pipeline/detail/memory.h"
#include "util/system.h"

namespace lacuna {
namespace detail {

std::vector<double> SlabLayout::cuts() const {
  if (!(height > 0)) return {bottom, bottom + whole};
  std::vector<double> out = {bottom};
  while (out.back() < top) out.push_back(bottom + double(out.size()) * height);
  return out;
}

std::vector<ZSlab> SlabLayout::slabs() const {
  const std::vector<double> c = cuts();
  std::vector<ZSlab> out;
  for (size_t i = 0; i + 1 < c.size(); ++i) out.push_back({c[i] - halo, c[i + 1] + halo});
  return out;
}

SlabLayout slab_layout(const MemoryEstimator& estimator, const ObjectExtent& extent, double h, double band, double unit,
                       double slab_mm, uint64_t budget, const std::string& what) {
  const double leaf = 8 * h;
  SlabLayout l;
  l.halo = std::ceil((extent.halo_mm + band + 2 * h) / leaf) * leaf;
  l.bottom = std::floor((extent.box.min.z - band - h) / unit) * unit;
  l.top = extent.box.max.z + band + 2 * h;
  l.whole = std::ceil((l.top - l.bottom) / unit) * unit;
  auto slabs_of = [&](double height) {
    SlabLayout trial = l;
    trial.height = height;
    return trial.slabs();
  };
  if (slab_mm > 0) {
    l.height = std::ceil(slab_mm / unit - 1e-9) * unit;
  } else if (estimator.bytes() > budget) {
    // The highest slabs that fit (in units): the estimate grows with their height.
    size_t lo = 1, hi = size_t(std::ceil(l.whole / unit));
    if (estimator.bytes(slabs_of(unit)) > budget)
      throw ResourceLimit(what + ": even slabs of " + fixed(unit, 4) + " mm (with a halo of " + fixed(l.halo, 4) +
                          " mm below and above) need more than the budget of " + format_bytes(budget) +
                          "; use a larger voxel size or more memory");
    while (hi - lo > 1) {
      const size_t mid = (lo + hi) / 2;
      (estimator.bytes(slabs_of(double(mid) * unit)) <= budget ? lo : hi) = mid;
    }
    l.height = double(lo) * unit;
  }
  return l;
}

std::vector<std::pair<std::string, double>> stage_totals(const StageTimer& timer) {
  std::vector<std::pair<std::string, double>> totals;
  for (const auto& [name, seconds] : timer.seconds()) {
    auto same = std::find_if(totals.begin(), totals.end(), [&](const auto& t) { return t.first == name; });
    if (same == totals.end()) totals.emplace_back(name, seconds);
    else same->second += seconds;
  }
  return totals;
}

}  // namespace detail
}  // namespace lacuna
