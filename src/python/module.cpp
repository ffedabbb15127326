// The extension module lacuna._lacuna, re-exported by the package lacuna (src/python/lacuna).
#include <pybind11/pybind11.h>

#include "python/convert.h"
#include "python/objects.h"

PYBIND11_MODULE(_lacuna, m) {
  namespace py = pybind11;
  m.doc() =
      "Lacuna: volumetric solid modeling for additive manufacturing. Solids made from the recipe's inputs and "
      "operations, meshed into closed, manifold, outward, self-intersection-free surfaces; recipes run into checked "
      "files; the generators (CIFS, NURBS, space-filling curves, fill patterns, fractal Voronoi, lacunar faces) called "
      "directly. Lengths are millimetres.";
  m.attr("__version__") = LACUNA_VERSION;
  lacuna::python::register_errors(m);
  lacuna::python::add_mesh(m);
  lacuna::python::add_solids(m);
  lacuna::python::add_generators(m);
}
