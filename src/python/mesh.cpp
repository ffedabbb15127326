// lacuna.Mesh, lacuna.Grid and reading meshes.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "export/mesh_io.h"
#include "export/output_files.h"
#include "export/report.h"
#include "pipeline/check_file.h"
#include "pipeline/draco_output.h"
#include "pipeline/report.h"
#include "pipeline/fea_output.h"
#include "pipeline/mesh_object.h"
#include "python/convert.h"
#include "python/objects.h"
#include "recipe/recipe.h"
#include "solids/simplify.h"

namespace lacuna {
namespace python {
namespace {

namespace fs = std::filesystem;

// A read-only array viewing memory that `owner` keeps alive.
template <class T>
py::array view(const std::shared_ptr<const TriMesh>& owner, const T* data, size_t rows, size_t row_bytes) {
  auto* keep = new std::shared_ptr<const TriMesh>(owner);
  py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<const TriMesh>*>(p); });
  py::array_t<T> a({py::ssize_t(rows), py::ssize_t(3)}, {py::ssize_t(row_bytes), py::ssize_t(sizeof(T))},
                   rows ? data : nullptr, base);
  a.attr("flags").attr("writeable") = false;
  return std::move(a);
}

py::array box_array(const Box3& box) {
  py::array_t<double> a({2, 3});
  double* out = a.mutable_data();
  for (int k = 0; k < 3; ++k) {
    out[k] = box.empty() ? NAN : box.min[k];
    out[3 + k] = box.empty() ? NAN : box.max[k];
  }
  return std::move(a);
}

// A tetrahedral output's settings, read as a recipe reads an output's "fea" object (same checks and
// messages).
FeaSettings fea_settings(const std::string& file, const py::dict& options) {
  nlohmann::json recipe = {{"inputs", {{"mesh", {{"type", "sphere"}, {"radius_mm", 1}}}}},
                           {"outputs", {{{"of", "mesh"}, {"file", file}}}}};
  if (!options.empty()) recipe["outputs"][0]["fea"] = to_json(options, "fea");
  return parse_recipe(recipe.dump(), "Mesh.save").outputs.front().fea;
}

// A Draco file within quantize_mm (default: a tenth of the voxel the mesh was made on), decoded from
// the file and checked; its figures and check as a dict.
py::object save_draco(const Mesh& mesh, const std::string& path, const py::dict& keys) {
  double quantize_mm = 0;
  for (const auto& [key, value] : keys) {
    if (py::str(key).cast<std::string>() != "quantize_mm")
      throw py::value_error("Mesh.save: a .drc file takes quantize_mm only, not " + py::str(key).cast<std::string>());
    quantize_mm = value.cast<double>();
    if (!(quantize_mm > 0) || !std::isfinite(quantize_mm))
      throw py::value_error("Mesh.save: quantize_mm: expected a positive length in mm");
  }
  if (quantize_mm == 0) {
    if (!(mesh.voxel_size_mm > 0))
      throw py::value_error("Mesh.save: give quantize_mm (mm) for a .drc file of a mesh that was not meshed from a "
                            "voxel grid (Solid.mesh and Grid.mesh meshes use a tenth of their voxel)");
    quantize_mm = mesh.voxel_size_mm / 10;
  }
  const DracoOutput out = released([&] {
    OutputTransaction transaction;
    DracoOutput d = write_checked_draco(transaction.stage(path), *mesh.data, quantize_mm, uint64_t{8} << 30);
    if (d.check.valid()) transaction.commit();
    return d;
  });
  nlohmann::json report = check_report_json(out.check);
  report["file"] = path;
  report["draco"] = to_json(out.figures);
  if (!out.check.valid()) {
    std::string message = path + ": no Draco quantization keeps the mesh valid; nothing was written";
    raise(errors().check_failed, message, from_json(report));
  }
  return from_json(report);
}

py::object save(const Mesh& mesh, const std::string& path, const std::string& name, const py::dict& fea) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  const std::string object_name = name.empty() ? fs::path(path).stem().string() : name;
  if (ext == ".stl" || ext == ".3mf") {
    if (!fea.empty()) throw py::value_error("Mesh.save: tetrahedral settings need a .msh, .inp, .vtu or .mesh file");
    released([&] {
      OutputTransaction transaction;
      const std::string temp = transaction.stage(path);
      if (ext == ".stl") {
        write_stl(temp, *mesh.data, "Lacuna " LACUNA_VERSION " " + object_name);
      } else {
        ThreeMfInfo info;
        info.object_name = object_name;
        info.metadata = {{"Application", "Lacuna " LACUNA_VERSION}, {"Title", object_name}};
        write_3mf(temp, *mesh.data, info);
      }
      transaction.commit();
    });
    return py::none();
  }
  if (ext == ".drc") return save_draco(mesh, path, fea);
  if (ext != ".msh" && ext != ".inp" && ext != ".vtu" && ext != ".mesh")
    throw InvalidInput(path + ": expected a file name ending in .stl, .3mf or .drc (or .msh, .inp, .vtu, .mesh for "
                              "tetrahedra)");
  const FeaSettings settings = fea_settings(fs::path(path).filename().string(), fea);
  const TetCheck check = released([&] { return write_tetrahedra(*mesh.data, path, settings); });
  nlohmann::json report = fea_report_json(check);
  report["file"] = path;
  if (!check.valid()) {
    std::string message = path + ": the tetrahedral mesh failed its checks; nothing was written";
    for (const std::string& p : check.problems) message += "\n  " + p;
    raise(errors().check_failed, message, from_json(report));
  }
  return from_json(report);
}

py::object check(const Mesh& mesh, bool printability, double min_wall_mm, double min_hole_mm,
                 const py::handle& build_direction, double critical_angle_deg, const py::object& voxel_size_mm) {
  CheckFileOptions options;
  options.printability = printability;
  options.min_wall_mm = min_wall_mm;
  options.min_hole_mm = min_hole_mm;
  options.build_direction = to_vec3(build_direction, "build_direction");
  if (!(norm(options.build_direction) > 0)) throw py::value_error("build_direction: expected a non-zero direction");
  options.critical_angle_deg = critical_angle_deg;
  options.voxel_size_mm = voxel_size_mm.is_none() ? 0.0 : voxel_size_mm.cast<double>();
  const FileCheck result = released([&] { return check_solid(*mesh.data, mesh.label, options); });
  py::dict report = from_json(to_json(result));
  report["valid"] = result.valid();
  return std::move(report);
}

}  // namespace

TriMesh mesh_from_arrays(const py::handle& vertices, const py::handle& faces) {
  TriMesh mesh;
  mesh.positions_mm = to_points(vertices, "vertices");
  py::array_t<int64_t, py::array::c_style | py::array::forcecast> f;
  try {
    f = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(faces);
  } catch (const py::error_already_set&) {
  }
  if (!f || f.ndim() != 2 || f.shape(1) != 3) throw py::value_error("faces: expected an M x 3 array of vertex indices");
  const int64_t* idx = f.data();
  const int64_t n = int64_t(mesh.positions_mm.size());
  mesh.triangles.resize(size_t(f.shape(0)));
  for (size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int64_t i = idx[3 * t + size_t(k)];
      if (i < 0 || i >= n)
        throw py::value_error("faces[" + std::to_string(t) + "]: expected vertex indices from 0 to " +
                              std::to_string(n) + " - 1");
      mesh.triangles[t][size_t(k)] = uint32_t(i);
    }
  return mesh;
}

const MeshCheckReport& Mesh::figures() const {
  if (!summary) {
    CheckOptions options;
    options.self_intersections = false;
    const std::shared_ptr<const TriMesh> mesh = data;
    summary = std::make_shared<const MeshCheckReport>(released([&] { return check_mesh(*mesh, options); }));
  }
  return *summary;
}

Mesh make_mesh(TriMesh&& mesh, std::string label, double voxel_size_mm) {
  Mesh m;
  m.data = std::make_shared<const TriMesh>(std::move(mesh));
  m.label = std::move(label);
  m.voxel_size_mm = voxel_size_mm;
  return m;
}

double deviation_mm(const py::object& simplify_mm, double voxel_size_mm) {
  if (simplify_mm.is_none()) return kDefaultSimplifyVoxels * voxel_size_mm;
  const double d = simplify_mm.cast<double>();
  if (!(d >= 0) || !std::isfinite(d))
    throw InvalidInput("simplify_mm: expected a deviation of at least 0 mm (0: no simplification)");
  return d;
}

void add_mesh(py::module_& m) {
  py::class_<Mesh>(m, "Mesh",
                   "A triangle mesh in millimetres, counter-clockwise seen from outside. Immutable: `vertices` and "
                   "`faces` are read-only numpy views of the mesh's own memory (no copy).")
      .def(py::init([](const py::handle& vertices, const py::handle& faces) {
             return make_mesh(mesh_from_arrays(vertices, faces), "mesh");
           }),
           py::arg("vertices"), py::arg("faces"),
           "A mesh copied from an N x 3 array of vertex positions (mm) and an M x 3 array of vertex indices.")
      .def_property_readonly(
          "vertices",
          [](const Mesh& self) {
            const auto& p = self.data->positions_mm;
            return view<double>(self.data, p.empty() ? nullptr : &p[0].x, p.size(), sizeof(Vec3d));
          },
          "N x 3 float64 vertex positions (mm), a read-only view.")
      .def_property_readonly(
          "faces",
          [](const Mesh& self) {
            const auto& t = self.data->triangles;
            return view<uint32_t>(self.data, t.empty() ? nullptr : t[0].data(), t.size(), sizeof(t[0]));
          },
          "M x 3 uint32 vertex indices of the triangles, counter-clockwise seen from outside; a read-only view.")
      .def_property_readonly(
          "volume_mm3", [](const Mesh& self) { return self.figures().volume_mm3; },
          "Enclosed volume (mm^3), signed: positive for an outward-oriented solid.")
      .def_property_readonly(
          "volume", [](const Mesh& self) { return self.figures().volume_mm3; }, "The same as volume_mm3 (mm^3).")
      .def_property_readonly(
          "area_mm2", [](const Mesh& self) { return self.figures().area_mm2; }, "Surface area (mm^2).")
      .def_property_readonly(
          "area", [](const Mesh& self) { return self.figures().area_mm2; }, "The same as area_mm2 (mm^2).")
      .def_property_readonly(
          "genus", [](const Mesh& self) { return self.figures().genus; },
          "Sum over components of (2 - Euler characteristic) / 2.")
      .def_property_readonly(
          "components", [](const Mesh& self) { return self.figures().components; },
          "Connected components (through shared vertices).")
      .def_property_readonly(
          "bounding_box", [](const Mesh& self) { return box_array(self.figures().bounding_box); },
          "2 x 3 array: the smallest and the largest corner (mm).")
      .def("check", &check, py::arg("printability") = false, py::arg("min_wall_mm") = 0.0, py::arg("min_hole_mm") = 0.0,
           py::arg("build_direction") = std::vector<double>{0, 0, 1}, py::arg("critical_angle_deg") = 45.0,
           py::arg("voxel_size_mm") = py::none(),
           "Every check `lacuna check` runs, as the dict `lacuna check --json` prints (plus \"valid\"): closed, "
           "manifold, outward, free of self-intersections and degenerate faces, positive volume; with printability, "
           "trapped voids, walls thinner than min_wall_mm and holes narrower than min_hole_mm (mm, 0: not checked), "
           "overhang beyond critical_angle_deg (degrees) facing down from build_direction, analysed on a level set of "
           "voxel_size_mm (default a quarter of the smallest size asked about).")
      .def(
          "save",
          [](const Mesh& self, const py::handle& path, const std::string& name, const py::kwargs& fea) {
            return save(self, path_of(path), name, fea);
          },
          py::arg("path"), py::arg("name") = "",
          "Writes the mesh: .stl (binary), .3mf (one object called `name`, default the file's stem), .drc (Draco, "
          "no vertex moved further than the keyword quantize_mm, default a tenth of the voxel it was meshed on; "
          "decoded again and checked; returns the check and the compression), or tetrahedra "
          "(TetGen) in .msh, .inp, .vtu or .mesh with the keys of a recipe output's \"fea\" object as keyword "
          "arguments (max_tet_volume_mm3, quality, min_dihedral_deg, preserve_surface, msh_version, element, "
          "time_limit_s); the surface must pass every check. Written through a temporary file: all or nothing. "
          "Returns None, or for tetrahedra the report (nodes, tets, volume_mm3, ...).")
      .def(
          "simplify",
          [](const Mesh& self, double max_deviation_mm) {
            SimplifyOptions options;
            options.max_deviation_mm = max_deviation_mm;
            return make_mesh(released([&] { return simplify_mesh(*self.data, options); }), self.label);
          },
          py::arg("max_deviation_mm"),
          "A copy simplified with every collapse guarded (a valid solid stays valid), each vertex within "
          "max_deviation_mm (mm) of the surface.")
      .def("__repr__", [](const Mesh& self) {
        return "<lacuna.Mesh " + std::to_string(self.data->positions_mm.size()) + " vertices, " +
               std::to_string(self.data->triangles.size()) + " triangles>";
      });

  m.def(
      "read_mesh",
      [](const py::handle& path) {
        const std::string p = path_of(path);
        return make_mesh(released([&] { return read_mesh(p); }), p);
      },
      py::arg("path"),
      "Reads an STL (binary or ASCII), OBJ, PLY or 3MF file into a Mesh (STL vertices welded where their float "
      "coordinates are identical).");

  py::class_<Grid>(m, "Grid", "A solid as a narrow-band level set (signed distance, negative inside), immutable.")
      .def_property_readonly(
          "voxel_size_mm", [](const Grid& g) { return g.volume.voxel_size_mm(); }, "Voxel edge (mm).")
      .def_property_readonly(
          "band_voxels", [](const Grid& g) { return g.volume.options().half_band_voxels; },
          "Half width of the narrow band, in voxels.")
      .def_property_readonly(
          "active_voxels", [](const Grid& g) { return g.volume.active_voxel_count(); }, "Voxels stored in the band.")
      .def_property_readonly(
          "memory_bytes", [](const Grid& g) { return g.volume.memory_bytes(); }, "Memory the grid holds (bytes).")
      .def_property_readonly(
          "voxel_volume_mm3", [](const Grid& g) { return g.volume.voxel_volume_mm3(); },
          "Volume counted voxel by voxel with a linear ramp across the band (mm^3; about a voxel "
          "layer accurate: a mesh's volume is the precise figure).")
      .def_property_readonly(
          "bounding_box", [](const Grid& g) { return box_array(g.volume.bounding_box()); },
          "2 x 3 array: the corners of the voxels inside or near the surface (mm).")
      .def(
          "distance",
          [](const Grid& g, const py::handle& points) {
            const std::vector<Vec3d> p = to_points(points, "points");
            std::vector<double> d(p.size());
            released([&] {
              for (size_t i = 0; i < p.size(); ++i) d[i] = g.volume.distance_at(p[i]);
            });
            return numbers_array(d);
          },
          py::arg("points"),
          "Signed distance (mm) at each of N x 3 points, trilinearly interpolated; +band outside the band.")
      .def(
          "mesh",
          [](const Grid& g, const py::object& simplify_mm, const py::object& max_memory_gb) {
            const double deviation = deviation_mm(simplify_mm, g.volume.voxel_size_mm());
            const uint64_t budget = budget_bytes(max_memory_gb);
            ObjectMesh r = released([&] { return mesh_volume(g.volume, deviation, g.label, budget); });
            return make_mesh(std::move(r.mesh), g.label, g.volume.voxel_size_mm());
          },
          py::arg("simplify_mm") = py::none(), py::arg("max_memory_gb") = py::none(),
          "Its surface (marching tetrahedra: closed, manifold, outward, free of self-intersections), simplified "
          "to simplify_mm (mm; None: a fifth of the voxel, 0: not simplified). Refuses (ResourceLimitError) a mesh "
          "that would not fit max_memory_gb (GB; None: half the machine's memory).")
      .def("__repr__", [](const Grid& g) {
        return "<lacuna.Grid " + std::to_string(g.volume.active_voxel_count()) + " active voxels of " +
               std::to_string(g.volume.voxel_size_mm()) + " mm>";
      });
}

}  // namespace python
}  // namespace lacuna
