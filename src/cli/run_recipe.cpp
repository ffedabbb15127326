#include "cli/run_recipe.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "cli/exit_codes.h"
#include "errors.h"
#include "cli/fea_output.h"
#include "export/fea.h"
#include "export/mesh_io.h"
#include "export/output_files.h"
#include "export/report.h"
#include "recipe/recipe.h"
#include "solids/budget.h"
#include "solids/check.h"
#include "solids/components.h"
#include "solids/decimate.h"
#include "solids/infill.h"
#include "solids/parameterize.h"
#include "solids/printability.h"
#include "solids/repair.h"
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

// A hull must be a valid closed solid (closed, manifold, outward, no self-intersections) unless
// the recipe asks for explicit repairs; a broken one is an error that says what is wrong.
TriMesh checked_hull(TriMesh mesh, const MeshRepair& repair, double voxel_size_mm, const std::string& where) {
  MeshCheckReport r = check_mesh(mesh);
  if (r.valid()) return mesh;
  if (repair.any()) {
    RepairOptions options;
    options.weld_mm = repair.weld_mm;
    options.reorient = repair.reorient;
    options.close_gaps_mm = repair.close_gaps_mm;
    mesh = repair_mesh(mesh, options, voxel_size_mm);
    r = check_mesh(mesh);
    if (r.valid()) return mesh;
  }
  // Overlapping shells and crossings are resolved as a union by the level set when allowed.
  if (repair.allow_overlaps && r.closed() && r.non_manifold_edges == 0 && r.triangles > 0 && r.non_finite_vertices == 0)
    return mesh;
  std::string problems;
  for (const std::string& p : r.problems()) problems += (problems.empty() ? "" : "; ") + p;
  throw InvalidInput(where + " is not a valid closed solid: " + problems + (repair.any() ? " (after the repairs asked for)" : "") +
                     ". Repair it explicitly with \"repair\": {\"weld_mm\", \"reorient\", \"close_gaps_mm\", "
                     "\"allow_overlaps\"}, or thicken an open surface with type \"surface\"");
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
      in.geometry.solids.push_back(checked_hull(std::move(mesh), in.repair, recipe.voxel_size_mm, where + ": " + file.string()));
    } else {
      in.geometry.surfaces.push_back(ThickSurface{std::move(mesh), in.surface_thickness_mm});
    }
  }
  // Hulls given inline are held to the same standard.
  for (RecipeInput& in : recipe.inputs)
    if (in.type == "mesh" && in.mesh_file.empty())
      for (TriMesh& m : in.geometry.solids)
        m = checked_hull(std::move(m), in.repair, recipe.voxel_size_mm, recipe.file + ": " + in.json_path);
}

// Inputs built from other inputs (lattices fitted to a hull, grades by depth in it), in order.
void resolve_inputs(Recipe& recipe, const VolumeOptions& vopt) {
  auto find = [&](const std::string& name) -> const RecipeInput& {
    for (const RecipeInput& in : recipe.inputs)
      if (in.name == name) return in;
    throw std::logic_error("unknown input " + name);
  };
  RecipeContext context;
  context.box_of = [&](const std::string& name) { return bounding_box(find(name).geometry); };
  context.depth_in = [&](const std::string& name, double max_depth) {
    // A field for grading needs no finer voxels than a tenth of its range.
    VolumeOptions wide;
    wide.voxel_size_mm = std::max(vopt.voxel_size_mm, max_depth / 10);
    wide.half_band_voxels = max_depth / wide.voxel_size_mm + 2;
    auto volume = std::make_shared<Volume>(voxelize(find(name).geometry, wide));
    return std::function<double(const Vec3d&)>(
        [volume, max_depth](const Vec3d& p) { return std::clamp(-volume->distance_at(p), 0.0, max_depth); });
  };
  context.signed_distance_in = [&](const std::string& name, double inside, double outside) {
    // Fine enough to place nodes within a few percent of a cell, no finer than the part's voxels.
    const double range = std::max(inside, outside);
    VolumeOptions wide;
    wide.voxel_size_mm = std::max(vopt.voxel_size_mm, range / 20);
    wide.half_band_voxels = range / wide.voxel_size_mm + 2;
    auto volume = std::make_shared<Volume>(voxelize(find(name).geometry, wide));
    return std::function<double(const Vec3d&)>([volume](const Vec3d& p) { return volume->distance_at(p); });
  };
  context.volume_of = [&](const std::string& name) { return voxelize(find(name).geometry, vopt).voxel_volume_mm3(); };
  context.surface_of_mesh = [](const std::string& file, const std::string& where) {
    try {
      return mesh_patch_map(read_mesh(file), file);
    } catch (const InvalidInput& e) {
      throw InvalidInput(where + ": " + e.what());
    } catch (const IoError& e) {
      throw IoError(where + ": " + e.what());
    }
  };
  for (RecipeInput& in : recipe.inputs) {
    if (!in.resolve) continue;
    for (const std::string& dep : in.depends_on)
      if (find(dep).resolve)
        throw InvalidInput(recipe.file + ": " + in.json_path + ": \"" + dep + "\" is itself built from another input");
    in.resolve(in, context);
  }
}

// The objects an output writes: its group, or its one object.
std::vector<std::string> members(const RecipeOutput& out) {
  return out.group.empty() ? std::vector<std::string>{out.object} : out.group;
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
  for (const RecipeOutput& out : recipe.outputs)
    for (const std::string& name : members(out)) stack.push_back(name);
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
    for (const std::string& name : members(out))
      if (meshed.insert(name).second) ++plan.uses[name];
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
    if (op.kind == RecipeOperation::Kind::kOffset || op.kind == RecipeOperation::Kind::kShell ||
        op.kind == RecipeOperation::Kind::kInfill) {
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
  for (const RecipeOutput& out : recipe.outputs)
    for (const std::string& name : members(out)) mesh_of(objects[name].voxels);
  return total;
}

std::string refusal(const std::string& what, uint64_t need, uint64_t budget, const VolumeOptions& vopt) {
  // Memory goes with the surface resolved, about 1 / voxel size^2.
  double scale = std::sqrt(double(need) / double(budget)) * 1.05;
  return what + " needs about " + format_bytes(need) + ", more than the budget of " + format_bytes(budget) +
         " (--max-memory); a voxel size of " + fixed(vopt.voxel_size_mm * scale, 3) + " mm or larger would fit" +
         " (now " + fixed(vopt.voxel_size_mm, 4) + " mm)";
}

nlohmann::json features_json(const std::vector<PrintFeature>& features) {
  nlohmann::json list = nlohmann::json::array();
  for (const PrintFeature& f : features)
    list.push_back({{"volume_mm3", f.volume_mm3}, {"location", {f.location_mm.x, f.location_mm.y, f.location_mm.z}}});
  return list;
}

nlohmann::json printability_json(const PrintabilityReport& r) {
  return {{"trapped_voids", features_json(r.trapped_voids)},
          {"thin_walls", features_json(r.thin_walls)},
          {"small_holes", features_json(r.small_holes)},
          {"overhang_area_mm2", r.overhang_area_mm2},
          {"down_facing_area_mm2", r.down_facing_area_mm2}};
}

// Printability of an object before it is meshed; with "fix", drain holes are drilled from its
// trapped voids (the object changes) and it is analysed again.
nlohmann::json check_printability(Volume& volume, const PrintabilitySettings& settings, std::vector<std::string>& problems) {
  PrintabilityOptions options;
  options.min_wall_mm = settings.min_wall_mm;
  options.min_hole_mm = settings.min_hole_mm;
  options.build_direction = settings.build_direction;
  options.critical_angle_deg = settings.critical_angle_deg;
  PrintabilityReport report = analyze_printability(volume, options);
  size_t drilled = 0, thickened = 0;
  if (settings.on_failure == PrintabilitySettings::OnFailure::kFix && !report.ok()) {
    // Thin walls first (growing them can seal nothing new), then drain holes.
    if (!report.thin_walls.empty()) {
      thickened = report.thin_walls.size();
      volume = thicken_thin_walls(volume, report, settings.min_wall_mm);
      report = analyze_printability(volume, options);
    }
    if (!report.trapped_voids.empty()) {
      drilled = report.trapped_voids.size();
      volume = drill_drain_holes(volume, report.trapped_voids, settings.drain_hole_mm, options, settings.drain_down);
      report = analyze_printability(volume, options);
    }
  }
  nlohmann::json j = printability_json(report);
  j["drain_holes"] = drilled;
  j["thickened_walls"] = thickened;
  if (settings.on_failure != PrintabilitySettings::OnFailure::kReport) {
    if (!report.trapped_voids.empty()) problems.push_back(std::to_string(report.trapped_voids.size()) + " trapped voids (powder or resin cannot drain)");
    if (!report.thin_walls.empty()) problems.push_back(std::to_string(report.thin_walls.size()) + " walls thinner than " + fixed(settings.min_wall_mm, 4) + " mm");
    if (!report.small_holes.empty()) problems.push_back(std::to_string(report.small_holes.size()) + " holes narrower than " + fixed(settings.min_hole_mm, 4) + " mm");
  }
  return j;
}

// Adds an object's printability findings and relative density to an output's report entry.
void annotate(nlohmann::json& entry, const nlohmann::json& printability, const std::vector<std::string>& problems,
              const std::map<std::string, double>& hull_volume, const std::string& object) {
  if (!printability.is_null()) entry["printability"] = printability;
  for (const std::string& p : problems) {
    entry["checks"]["problems"].push_back(p);
    entry["checks"]["valid"] = false;
  }
  auto hull = hull_volume.find(object);
  if (hull != hull_volume.end() && hull->second > 0 && entry.contains("volume_mm3"))
    entry["relative_density"] = entry["volume_mm3"].get<double>() / hull->second;
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
  resolve_inputs(recipe, vopt);
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
    std::map<std::string, double> hull_volume;  // of infill operations, for their relative density
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
        case RecipeOperation::Kind::kInfill: {
          Volume hull = take(op.operands[0]), structure = take(op.operands[1]);
          require_mesh_memory(hull, budget, recipe.file + ": " + op.json_path, vopt);
          // Fused by a voxel unless told otherwise (and never through the whole skin).
          double fuse = op.distance_mm >= 0 ? op.distance_mm : std::min(vopt.voxel_size_mm, 0.5 * op.thickness_mm);
          v = in_context(recipe.file + ": " + op.json_path, [&] { return infill(hull, structure, op.thickness_mm, fuse); });
          hull_volume[op.name] = hull.voxel_volume_mm3();
          break;
        }
      }
      volumes[op.name] = v;
    }

    // Each exported object is meshed once and written in every format asked for; then every
    // written file is read back and checked as the file it is.
    std::vector<std::string> objects;
    for (const RecipeOutput& out : recipe.outputs)
      for (const std::string& name : members(out))
        if (std::find(objects.begin(), objects.end(), name) == objects.end()) objects.push_back(name);
    // The meshes of a group wait here until its last object is meshed.
    std::map<const RecipeOutput*, std::map<std::string, TriMesh>> pending;
    for (const std::string& object : objects) {
      timer.start("mesh");
      Volume volume = take(object);
      require_mesh_memory(volume, budget, recipe.file + ": meshing \"" + object + "\"", vopt);
      nlohmann::json printability;
      std::vector<std::string> print_problems;
      if (recipe.printability.enabled) {
        timer.start("printability");
        printability = check_printability(volume, recipe.printability, print_problems);
        timer.start("mesh");
      }
      const uint64_t voxels = volume.active_voxel_count();
      TriMesh mesh = extract_surface(volume);
      const double h = volume.voxel_size_mm();
      const size_t filled = fill_small_cavities(mesh, h * h * h);
      const size_t specks = remove_small_specks(mesh, h * h * h);
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
        if (!out.group.empty()) {
          if (std::find(out.group.begin(), out.group.end(), object) == out.group.end()) continue;
          std::map<std::string, TriMesh>& parts = pending[&out];
          parts[object] = surface_for(out.decimate_mm);
          if (parts.size() < out.group.size()) continue;
          timer.start("write");
          const std::string final_path = (out_dir / out.file).string();
          std::string temp = transaction.stage(final_path);
          std::vector<ThreeMfObject> objects3mf;
          for (const std::string& name : out.group) objects3mf.push_back({&parts[name], name});
          ThreeMfInfo info;
          info.metadata = {{"Application", "Lacuna " LACUNA_VERSION}, {"Title", recipe.name}};
          if (!recipe.description.empty()) info.metadata.push_back({"Description", recipe.description});
          write_3mf(temp, objects3mf, info);
          pending.erase(&out);
          written.push_back({&out, temp, final_path});
          continue;
        }
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
        entry["subvoxel_cavities_filled"] = filled;
        entry["subvoxel_specks_removed"] = specks;
        annotate(entry, printability, print_problems, hull_volume, out.object);
        outputs.push_back(entry);
        all_valid = all_valid && entry["checks"]["valid"].get<bool>();
      }
      mesh = TriMesh();
      decimated.clear();
      timer.start("check");
      for (const Written& w : written) {
        ReadOptions read;
        read.max_memory_bytes = budget;
        std::vector<std::string> names;
        if (!w.out->group.empty()) read.object_names = &names;
        TriMesh back = read_mesh(w.temp, mesh_format_from_path(w.final_path), read);
        MeshCheckReport report = check_mesh(back);
        nlohmann::json entry = check_report_json(report);
        entry["file"] = w.final_path;
        entry["format"] = w.out->format;
        entry["object"] = w.out->object;
        if (!w.out->group.empty()) {
          // The package as written holds every object once, in order; together they are checked as one
          // solid, so they are also free of intersections with each other.
          entry["objects"] = names;
          if (names != w.out->group) {
            entry["checks"]["valid"] = false;
            entry["checks"]["objects_as_asked"] = false;
          }
        }
        entry["part_name"] = w.out->part_name;
        entry["voxels"] = voxels;
        entry["subvoxel_cavities_filled"] = filled;
        entry["subvoxel_specks_removed"] = specks;
        if (w.out->decimate_mm > 0) entry["decimated_mm"] = w.out->decimate_mm;
        annotate(entry, printability, print_problems, hull_volume, w.out->object);
        outputs.push_back(entry);
        all_valid = all_valid && entry["checks"]["valid"].get<bool>();
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
    nlohmann::json inputs_report = nlohmann::json::object();
    for (const RecipeInput& in : recipe.inputs)
      if (!in.report.is_null()) inputs_report[in.name] = in.report;
    if (!inputs_report.empty()) result.report["inputs"] = inputs_report;
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
