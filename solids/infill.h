// A hull filled with a structure: a solid skin and the structure inside it, fused together
// (../shared/spec/pipeline.md, "Hull infill").
#pragma once

#include <vector>

#include "solids/volume.h"

namespace lacuna {

// The offsets of the hull an infill cuts at: its skin's inner surface (-skin) and the core the
// structure is kept in (-(skin - fuse)). Throws InvalidInput unless skin > 0 and 0 <= fuse < skin.
std::vector<double> infill_offsets(double skin_mm, double fuse_mm);

// (H minus erode(H, skin)) union (S intersect erode(H, skin - fuse)): the structure reaches `fuse`
// into the skin so the two are one solid. skin > 0; 0 <= fuse < skin.
Volume infill(const Volume& hull, const Volume& structure, double skin_mm, double fuse_mm);

// The same with the hull's offsets by infill_offsets() made already (offsets() of the hull, or
// mesh_offsets() of the closed mesh it was made from).
Volume infill(const Volume& hull, const Volume& structure, const std::vector<Volume>& hull_offsets);

}  // namespace lacuna
