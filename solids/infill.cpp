#include "solids/infill.h"

#include <cmath>

#include "errors.h"

namespace lacuna {

Volume infill(const Volume& hull, const Volume& structure, double skin_mm, double fuse_mm) {
  if (!(skin_mm > 0) || !std::isfinite(skin_mm)) throw InvalidInput("the skin thickness must be positive (mm)");
  if (!(fuse_mm >= 0 && fuse_mm < skin_mm)) throw InvalidInput("the fusing depth must be at least 0 and less than the skin");
  // The skin's inner surface and the core are two levels of one distance to the hull's surface.
  const std::vector<Volume> inner = offsets(hull, {-skin_mm, -(skin_mm - fuse_mm)});
  return unite(subtract(hull, inner[0]), intersect(structure, inner[1]));
}

}  // namespace lacuna
