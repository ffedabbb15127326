// The shipped systems (systems described in JSON are read in recipe/cifs_system.h).
#pragma once

#include <string>
#include <vector>

#include "cifs/automaton.h"

namespace lacuna {
namespace cifs {

// Names of the shipped fixed systems: sierpinski_triangle, sierpinski_tetrahedron,
// menger_sponge, cantor_dust_2d, cantor_dust_3d, koch_curve, takagi_curve, bspline_quadratic,
// bspline_cubic.
std::vector<std::string> library_names();

// A shipped system with its default control points (unit size, at the origin). Throws
// InvalidInput for an unknown name, suggesting the closest.
Cifs library_system(const std::string& name);

}  // namespace cifs
}  // namespace lacuna
