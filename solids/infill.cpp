#include "solids/infill.h"

#include <cmath>

#include "errors.h"

namespace lacuna {

Volume infill(const Volume& hull, const Volume& structure, double skin_mm, double fuse_mm) {
  if (!(skin_mm > 0) || !std::isfinite(skin_mm)) throw InvalidInput("the skin thickness must be positive (mm)");
  if (!(fuse_mm >= 0 && fuse_mm < skin_mm)) throw InvalidInput("the fusing depth must be at least 0 and less than the skin");
  Volume skin = shell(hull, skin_mm);
  Volume core = offset(hull, -(skin_mm - fuse_mm));
  return unite(skin, intersect(structure, core));
}

}  // namespace lacuna
