// The values the Python module hands out: meshes (lacuna.Mesh, numpy views of a TriMesh that is
// never copied) and level sets (lacuna.Grid), and the functions that add each part of the module.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <optional>
#include <string>

#include "geometry.h"
#include "solids/check.h"
#include "solids/volume.h"

namespace lacuna {
namespace python {

namespace py = pybind11;

// lacuna.Mesh: an immutable triangle mesh. Its arrays view the mesh's own memory.
struct Mesh {
  std::shared_ptr<const TriMesh> data;
  std::string label = "mesh";  // the file it was read from, or what made it, for reports
  double voxel_size_mm = 0;    // of the grid it was meshed from (0: not meshed here)
  // Figures from the checks without the self-intersection test, computed once when first asked for.
  mutable std::shared_ptr<const MeshCheckReport> summary;

  const MeshCheckReport& figures() const;
};

// lacuna.Grid: a narrow-band level set (negative inside), shared and immutable.
struct Grid {
  Volume volume;
  std::string label = "grid";
};

// A mesh taken over without copying.
Mesh make_mesh(TriMesh&& mesh, std::string label, double voxel_size_mm = 0);

// A mesh copied from an N x 3 array of positions and an M x 3 array of indices; throws ValueError
// for other shapes and for indices out of range.
TriMesh mesh_from_arrays(const py::handle& vertices, const py::handle& faces);

// The simplification deviation of a mesh() call: None gives the recipe's default for the voxel size.
double deviation_mm(const py::object& simplify_mm, double voxel_size_mm);

void add_mesh(py::module_& m);
void add_solids(py::module_& m);
void add_generators(py::module_& m);

}  // namespace python
}  // namespace lacuna
