// A hull filled with a structure: a solid skin and the structure inside it, fused together
// (../shared/spec/pipeline.md, "Hull infill").
#pragma once

#include "solids/volume.h"

namespace lacuna {

// (H minus erode(H, skin)) union (S intersect erode(H, skin - fuse)): the structure reaches `fuse`
// into the skin so the two are one solid. skin > 0; 0 <= fuse < skin.
Volume infill(const Volume& hull, const Volume& structure, double skin_mm, double fuse_mm);

}  // namespace lacuna
