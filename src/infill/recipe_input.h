// The "lattice" recipe input: a test lattice of tubes, fitted to a box or to another input,
// with a radius graded by a field.
#pragma once

namespace lacuna {

// Registers the infill input types (called once by the recipe reader).
void register_infill_inputs();

}  // namespace lacuna
