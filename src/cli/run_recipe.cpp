#include "cli/run_recipe.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "errors.h"
#include "cli/fea_output.h"
#include "export/fea.h"
#include "export/mesh_io.h"
#include "export/output_files.h"
#include "export/report.h"
#include "recipe/recipe.h"
#include "solids/budget.h"
#include "solids/check.h"
#include "solids/decimate.h"
#include "solids/extract.h"
#include "solids/voxelize.h"
#include "util/system.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

// float32 output keeps crossing points apart only while |coordinate| / voxel stays below this
// (see extract.h: crossings sit at least 1% of a voxel from grid points).
constexpr double kMaxCoordinateInVoxels = 131072.0;

std::string fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*g", digits, v);
  return text;
}

// Material region of every tetrahedron: the first region solid its centroid lies in, else the
// nearest one (tetrahedra straddling an interface go to the side holding their centroid).
void assign_regions(TetMesh& mesh, const std::vector<Volume>& regions) {
  mesh.regions.assign(mesh.tets.size(), 0);
  tbb::parallel_for(size_t(0), mesh.tets.size(), [&](size_t t) {
    const auto& tet = mesh.tets[t];
    Vec3d c = (mesh.nodes_mm[tet[0]] + mesh.nodes_mm[tet[1]] + mesh.nodes_mm[tet[2]] + mesh.nodes_mm[tet[3]]) * 0.25;
    double best = HUGE_VAL;
    for (size_t r = 0; r < regions.size(); ++r) {
      double d = regions[r].distance_at(c);
      if (d < 0) {
        mesh.regions[t] = int(r);
        return;
      }
      if (d < best) {
        best = d;
        mesh.regions[t] = int(r);
      }
    }
  });
}

// Runs `step`, prefixing any InvalidInput it throws with `where` (file and JSON path).
template <typename Step>
auto in_context(const std::string& where, Step&& step) {
  try {
    return step();
  } catch (const InvalidInput& e) {
    throw InvalidInput(where + ": " + e.what());
  }
}

void import_meshes(Recipe& recipe, uint64_t budget) {
  const fs::path base = fs::path(recipe.file).parent_path();
  for (RecipeInput& in : recipe.inputs) {
    if (in.mesh_role == RecipeInput::MeshRole::kNone) continue;
    fs::path file(in.mesh_file);
    if (file.is_relative()) file = base / file;
    const std::string where = recipe.file + ": " + in.json_path + ".file";
    std::error_code ec;
    if (!fs::exists(file, ec)) throw IoError(where + ": " + file.string() + " does not exist");
    ReadOptions read;
    read.max_memory_bytes = budget;
    TriMesh mesh;
    try {
      mesh = read_mesh(file.string(), read);
    } catch (const InvalidInput& e) {
      throw InvalidInput(where + ": " + e.what());
    } catch (const IoError& e) {
      throw IoError(where + ": " + e.what());
    } catch (const ResourceLimit& e) {
      throw ResourceLimit(where + ": " + e.what());
    }
    for (Vec3d& p : mesh.positions_mm) p = p * in.mesh_scale + in.mesh_translate_mm;
    if (in.mesh_role == RecipeInput::MeshRole::kSolid) {
      // The level-set conversion needs a closed surface; it tolerates orientation errors and
      // overlapping shells, so only openness is fatal here.
      CheckOptions quick;
      quick.self_intersections = false;
      MeshCheckReport r = check_mesh(mesh, quick);
      if (!r.closed() || r.degenerate_faces == r.triangles) {
        std::string message = where + ": " + file.string() + " is not a closed mesh (" +
                              std::to_string(r.boundary_edges) + " boundary edges); use type \"surface\" with " +
                              "\"thickness_mm\" to thicken an open surface";
        throw InvalidInput(message);
      }
      in.geometry.solids.push_back(std::move(mesh));
    } else {
      in.geometry.surfaces.push_back(ThickSurface{std::move(mesh), in.surface_thickness_mm});
    }
  }
}

struct Plan {
  std::map<std::string, const RecipeInput*> inputs;
  std::map<std::string, const RecipeOperation*> operations;
  std::map<std::string, int> uses;  // how many later steps and outputs read each object
  std::set<std::string> needed;
};

Plan make_plan(const Recipe& recipe) {
  Plan plan;
  for (const RecipeInput& in : recipe.inputs) plan.inputs[in.name] = &in;
  for (const RecipeOperation& op : recipe.operations) plan.operations[op.name] = &op;
  std::vector<std::string> stack;
  for (const RecipeOutput& out : recipe.outputs) stack.push_back(out.object);
  while (!stack.empty()) {
    std::string name = stack.back();
    stack.pop_back();
    if (!plan.needed.insert(name).second) continue;
    auto op = plan.operations.find(name);
    if (op != plan.operations.end())
      for (const std::string& o : op->second->operands) stack.push_back(o);
  }
  for (const RecipeOperation& op : recipe.operations)
    if (plan.needed.count(op.name))
      for (const std::string& o : op.operands) ++plan.uses[o];
  std::set<std::string> meshed;
  for (const RecipeOutput& out : recipe.outputs)
    if (meshed.insert(out.object).second) ++plan.uses[out.object];
  // Material regions of tetrahedral outputs are read after their object is meshed.
  for (const RecipeOutput& out : recipe.outputs)
    for (const std::string& name : out.fea.regions) {
      ++plan.uses[name];
      stack.push_back(name);
    }
  while (!stack.empty()) {
    std::string name = stack.back();
    stack.pop_back();
    if (!plan.needed.insert(name).second) continue;
    auto op = plan.operations.find(name);
    if (op != plan.operations.end())
      for (const std::string& o : op->second->operands) {
        ++plan.uses[o];
        stack.push_back(o);
      }
  }
  return plan;
}

// Memory for everything the plan builds, refused before any large allocation: every level set
// it keeps (conservatively, all of them at once) plus the largest surface it meshes and checks.
struct Estimate {
  uint64_t grid_bytes = 0;
  uint64_t mesh_bytes = 0;
  uint64_t voxels = 0;
  uint64_t triangles = 0;
  uint64_t bytes() const { return grid_bytes + mesh_bytes; }
};

Estimate estimate(const Recipe& recipe, const Plan& plan, const VolumeOptions& vopt) {
  struct Object {
    double area = 0;
    Box3 box;
    uint64_t voxels = 0;
  };
  std::map<std::string, Object> objects;
  Estimate total;
  auto mesh_of = [&](uint64_t voxels) {
    MemoryEstimate m = estimate_from_voxels(voxels, vopt);
    if (m.mesh_bytes > total.mesh_bytes) {
      total.mesh_bytes = m.mesh_bytes;
      total.triangles = m.triangles;
    }
  };
  for (const RecipeInput& in : recipe.inputs) {
    if (!plan.needed.count(in.name)) continue;
    MemoryEstimate e = in_context(recipe.file + ": " + in.json_path, [&] { return estimate_voxelize(in.geometry, vopt); });
    objects[in.name] = {e.surface_area_mm2, bounding_box(in.geometry), e.active_voxels};
    total.grid_bytes += e.grid_bytes;
    total.voxels += e.active_voxels;
  }
  for (const RecipeOperation& op : recipe.operations) {
    if (!plan.needed.count(op.name)) continue;
    Object o;
    const Object& first = objects[op.operands[0]];
    o.box = first.box;
    for (const std::string& name : op.operands) {
      o.area += objects[name].area;
      if (op.kind == RecipeOperation::Kind::kUnion) o.box.expand(objects[name].box);
    }
    VolumeOptions work = vopt;
    if (op.kind == RecipeOperation::Kind::kOffset || op.kind == RecipeOperation::Kind::kShell) {
      // Goes through the operand's surface mesh and a band as wide as the distance.
      double d = op.kind == RecipeOperation::Kind::kOffset ? std::fabs(op.distance_mm) : op.thickness_mm;
      mesh_of(first.voxels);
      work.half_band_voxels += d / vopt.voxel_size_mm;
      if (op.kind == RecipeOperation::Kind::kOffset && op.distance_mm > 0) {
        o.box.min -= Vec3d{d, d, d};
        o.box.max += Vec3d{d, d, d};
      }
      MemoryEstimate wide = estimate_from_voxels(band_voxels(o.area, o.box, work), work);
      total.grid_bytes += wide.grid_bytes;
    }
    o.voxels = band_voxels(o.area, o.box, vopt);
    MemoryEstimate e = estimate_from_voxels(o.voxels, vopt);
    total.grid_bytes += e.grid_bytes;
    total.voxels += e.active_voxels;
    objects[op.name] = o;
  }
  for (const RecipeOutput& out : recipe.outputs) mesh_of(objects[out.object].voxels);
  return total;
}

std::string refusal(const std::string& what, uint64_t need, uint64_t budget, const VolumeOptions& vopt) {
  // Memory goes with the surface resolved, about 1 / voxel size^2.
  double scale = std::sqrt(double(need) / double(budget)) * 1.05;
  return what + " needs about " + format_bytes(need) + ", more than the budget of " + format_bytes(budget) +
         " (--max-memory); a voxel size of " + fixed(vopt.voxel_size_mm * scale, 3) + " mm or larger would fit" +
         " (now " + fixed(vopt.voxel_size_mm, 4) + " mm)";
}

// Refuses, before meshing, a surface whose mesh and checks would not fit next to what is in use.
void require_mesh_memory(const Volume& v, uint64_t budget, const std::string& what, const VolumeOptions& vopt) {
  uint64_t need = estimate_from_voxels(v.active_voxel_count(), vopt).mesh_bytes + current_memory_bytes();
  if (need > budget) throw ResourceLimit(refusal(what, need, budget, vopt));
}

}  // namespace

RunResult run_recipe(const std::string& recipe_path, const RunOptions& options) {
  StageTimer timer;
  timer.start("read");
  Recipe recipe = load_recipe(recipe_path);
  if (options.voxel_size_mm > 0) recipe.voxel_size_mm = options.voxel_size_mm;
  if (!options.replace_outputs.empty()) {
    std::vector<RecipeOutput> outputs = options.replace_outputs;
    for (RecipeOutput& out : outputs)
      if (out.object.empty()) out.object = recipe.outputs.front().object;
    recipe.outputs = outputs;
  }
  const VolumeOptions vopt{recipe.voxel_size_mm, recipe.band_voxels};
  const uint64_t budget = options.max_memory_bytes ? options.max_memory_bytes : available_memory_bytes() / 2;

  import_meshes(recipe, budget);
  for (const RecipeInput& in : recipe.inputs)
    in_context(recipe.file + ": " + in.json_path, [&] { validate(in.geometry); });
  Plan plan = make_plan(recipe);

  // Refuse what cannot fit before building anything large.
  Box3 extent;
  for (const RecipeInput& in : recipe.inputs)
    if (plan.needed.count(in.name)) extent.expand(bounding_box(in.geometry));
  double reach = 0;
  for (int k = 0; k < 3; ++k) reach = std::max({reach, std::fabs(extent.min[k]), std::fabs(extent.max[k])});
  if (reach / vopt.voxel_size_mm > kMaxCoordinateInVoxels)
    throw ResourceLimit(recipe.file + ": the part reaches " + fixed(reach, 6) + " mm from the origin, more than " +
                        fixed(kMaxCoordinateInVoxels, 6) + " voxels of " + fixed(vopt.voxel_size_mm, 6) +
                        " mm; float32 output cannot keep such a fine surface exact. Move the part nearer the origin "
                        "or use a voxel size of at least " + fixed(reach / kMaxCoordinateInVoxels, 3) + " mm");
  Estimate need = estimate(recipe, plan, vopt);
  const uint64_t need_bytes = need.bytes();
  if (need_bytes > budget)
    throw ResourceLimit(refusal(recipe.file + ": this recipe (about " + fixed(double(need.voxels), 3) + " voxels and " +
                                    fixed(double(need.triangles), 3) + " triangles)",
                                need_bytes, budget, vopt));

  fs::path out_dir = options.output_dir.empty() ? fs::path(recipe.name + "-out") : fs::path(options.output_dir);
  std::error_code ec;
  bool created_dir = !fs::exists(out_dir, ec);
  if (!created_dir && !fs::is_directory(out_dir, ec))
    throw IoError(out_dir.string() + ": exists and is not a folder");
  fs::create_directories(out_dir, ec);
  if (ec) throw IoError(out_dir.string() + ": cannot create the output folder: " + ec.message());

  OutputTransaction transaction;
  RunResult result;
  nlohmann::json outputs = nlohmann::json::array();
  bool all_valid = true;
  try {
    // Volumes, built in recipe order and released after their last use.
    std::map<std::string, Volume> volumes;
    std::map<std::string, int> uses = plan.uses;
    auto take = [&](const std::string& name) {
      Volume v = volumes.at(name);
      if (--uses[name] == 0) volumes.erase(name);
      return v;
    };
    timer.start("voxelize");
    for (const RecipeInput& in : recipe.inputs) {
      if (!plan.needed.count(in.name)) continue;
      volumes[in.name] = in_context(recipe.file + ": " + in.json_path, [&] { return voxelize(in.geometry, vopt); });
    }
    timer.start("combine");
    for (const RecipeOperation& op : recipe.operations) {
      if (!plan.needed.count(op.name)) continue;
      Volume v;
      switch (op.kind) {
        case RecipeOperation::Kind::kUnion:
          v = take(op.operands[0]);
          for (size_t i = 1; i < op.operands.size(); ++i) v = unite(v, take(op.operands[i]));
          break;
        case RecipeOperation::Kind::kDifference:
          v = take(op.operands[0]);
          for (size_t i = 1; i < op.operands.size(); ++i) v = subtract(v, take(op.operands[i]));
          break;
        case RecipeOperation::Kind::kIntersection:
          v = take(op.operands[0]);
          for (size_t i = 1; i < op.operands.size(); ++i) v = intersect(v, take(op.operands[i]));
          break;
        case RecipeOperation::Kind::kOffset:
          v = take(op.operands[0]);
          require_mesh_memory(v, budget, recipe.file + ": " + op.json_path, vopt);
          v = offset(v, op.distance_mm);
          break;
        case RecipeOperation::Kind::kShell:
          v = take(op.operands[0]);
          require_mesh_memory(v, budget, recipe.file + ": " + op.json_path, vopt);
          v = shell(v, op.thickness_mm);
          break;
      }
      volumes[op.name] = v;
    }

    // Each exported object is meshed once and written in every format asked for; then every
    // written file is read back and checked as the file it is.
    std::vector<std::string> objects;
    for (const RecipeOutput& out : recipe.outputs)
      if (std::find(objects.begin(), objects.end(), out.object) == objects.end()) objects.push_back(out.object);
    for (const std::string& object : objects) {
      timer.start("mesh");
      Volume volume = take(object);
      const uint64_t voxels = volume.active_voxel_count();
      require_mesh_memory(volume, budget, recipe.file + ": meshing \"" + object + "\"", vopt);
      TriMesh mesh = extract_surface(volume);
      volume = Volume();
      if (mesh.triangles.empty())
        throw InvalidInput(recipe.file + ": \"" + object + "\" is empty: nothing is left to export");
      // Decimated versions, one per deviation asked for, checked like the rest on what is written.
      std::map<double, TriMesh> decimated;
      auto surface_for = [&](double deviation) -> const TriMesh& {
        if (deviation <= 0) return mesh;
        auto it = decimated.find(deviation);
        if (it == decimated.end()) {
          timer.start("decimate");
          DecimateOptions d;
          d.max_deviation_mm = deviation;
          it = decimated.emplace(deviation, decimate(mesh, d)).first;
        }
        return it->second;
      };
      struct Written {
        const RecipeOutput* out;
        std::string temp;
        std::string final_path;
      };
      std::vector<Written> written;
      for (const RecipeOutput& out : recipe.outputs) {
        if (out.object != object) continue;
        std::string final_path = (out_dir / out.file).string();
        const TriMesh& surface = surface_for(out.decimate_mm);
        if (out.format == "stl" || out.format == "3mf") {
          timer.start("write");
          std::string temp = transaction.stage(final_path);
          if (out.format == "stl") {
            write_stl(temp, surface, "Lacuna " LACUNA_VERSION " " + recipe.name + " " + out.part_name);
          } else {
            ThreeMfInfo info;
            info.object_name = out.part_name;
            info.metadata = {{"Application", "Lacuna " LACUNA_VERSION}, {"Title", recipe.name}};
            if (!recipe.description.empty()) info.metadata.push_back({"Description", recipe.description});
            write_3mf(temp, surface, info);
          }
          written.push_back({&out, temp, final_path});
          continue;
        }
        timer.start("tetrahedralize");
        FeaResult fea = make_fea_mesh(surface, out.fea);
        if (fea.valid() && !out.fea.regions.empty()) {
          std::vector<Volume> regions;
          for (const std::string& name : out.fea.regions) regions.push_back(volumes.at(name));
          assign_regions(fea.mesh, regions);
        }
        nlohmann::json entry = fea_report_json(fea);
        if (fea.valid()) {
          timer.start("write");
          FeaWriteOptions w;
          w.msh_version_2 = out.fea.msh_version_2;
          w.quadratic = out.fea.quadratic;
          write_fea(transaction.stage(final_path), fea_format_from_path(final_path), fea.mesh, w);
        }
        entry["file"] = final_path;
        entry["format"] = out.format;
        entry["object"] = out.object;
        entry["voxels"] = voxels;
        outputs.push_back(entry);
        all_valid = all_valid && fea.valid();
      }
      mesh = TriMesh();
      decimated.clear();
      timer.start("check");
      for (const Written& w : written) {
        ReadOptions read;
        read.max_memory_bytes = budget;
        TriMesh back = read_mesh(w.temp, mesh_format_from_path(w.final_path), read);
        MeshCheckReport report = check_mesh(back);
        nlohmann::json entry = check_report_json(report);
        entry["file"] = w.final_path;
        entry["format"] = w.out->format;
        entry["object"] = w.out->object;
        entry["part_name"] = w.out->part_name;
        entry["voxels"] = voxels;
        if (w.out->decimate_mm > 0) entry["decimated_mm"] = w.out->decimate_mm;
        outputs.push_back(entry);
        all_valid = all_valid && report.valid();
      }
      for (const RecipeOutput& out : recipe.outputs)
        if (out.object == object)
          for (const std::string& name : out.fea.regions)
            if (--uses[name] == 0) volumes.erase(name);
    }
    timer.stop();

    nlohmann::json stages = nlohmann::json::object();
    double total = 0;
    for (const auto& s : timer.seconds()) {
      stages[s.first] = s.second;
      total += s.second;
    }
    result.report = {
        {"lacuna_version", LACUNA_VERSION},
        {"recipe", recipe.file},
        {"name", recipe.name},
        {"voxel_size_mm", vopt.voxel_size_mm},
        {"band_voxels", vopt.half_band_voxels},
        {"seed", recipe.seed},
        {"valid", all_valid},
        {"outputs", outputs},
        {"stage_seconds", stages},
        {"total_seconds", total},
        {"peak_memory_bytes", peak_memory_bytes()},
        {"peak_memory_children_bytes", peak_child_memory_bytes()},
        {"memory_estimate_bytes", need_bytes},
        {"memory_budget_bytes", budget},
        {"threads", tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism)},
    };
    if (!all_valid) {
      transaction.rollback();
      if (created_dir) fs::remove(out_dir, ec);
      result.exit_code = kExitCheckFailed;
      return result;
    }
    std::string report_path = (out_dir / "report.json").string();
    if (options.write_report) write_text_file_atomically(transaction.stage(report_path), result.report.dump(2) + "\n");
    transaction.commit();
    for (const auto& o : outputs) result.written.push_back(o["file"].get<std::string>());
    if (options.write_report) result.written.push_back(report_path);
    return result;
  } catch (...) {
    transaction.rollback();
    if (created_dir) fs::remove(out_dir, ec);
    throw;
  }
}

}  // namespace lacuna
