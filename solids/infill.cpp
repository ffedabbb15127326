#include "solids/infill.h"

#include <cmath>

#include "errors.h"

namespace lacuna {

std::vector<double> infill_offsets(double skin_mm, double fuse_mm) {
  if (!(skin_mm > 0) || !std::isfinite(skin_mm)) throw InvalidInput("the skin thickness must be positive (mm)");
  if (!(fuse_mm >= 0 && fuse_mm < skin_mm)) throw InvalidInput("the fusing depth must be at least 0 and less than the skin");
  return {-skin_mm, -(skin_mm - fuse_mm)};
}

Volume infill(const Volume& hull, const Volume& structure, double skin_mm, double fuse_mm) {
  // The skin's inner surface and the core are two levels of one distance to the hull's surface.
  return infill(hull, structure, offsets(hull, infill_offsets(skin_mm, fuse_mm)));
}

Volume infill(const Volume& hull, const Volume& structure, const std::vector<Volume>& hull_offsets) {
  if (hull_offsets.size() != 2) throw InternalError("an infill takes the hull's two offsets");
  return unite(subtract(hull, hull_offsets[0]), intersect(structure, hull_offsets[1]));
}

}  // namespace lacuna
