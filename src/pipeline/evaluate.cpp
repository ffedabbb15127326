#include "pipeline/evaluate.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <variant>

#include "errors.h"
#include "pipeline/detail/memory.h"
#include "solids/budget.h"
#include "solids/components.h"
#include "solids/infill.h"
#include "solids/voxelize.h"
#include "util/system.h"

namespace lacuna {
namespace {

using detail::fixed;

// float32 output keeps crossing points apart only while |coordinate| / voxel stays below this
// (see extract.h: crossings sit at least 1% of a voxel from grid points).
constexpr double kMaxCoordinateInVoxels = 131072.0;

// Runs `step`, prefixing any InvalidInput it throws with `where` (file and JSON path).
template <typename Step>
auto in_context(const std::string& where, Step&& step) {
  try {
    return step();
  } catch (const InvalidInput& e) {
    throw InvalidInput(where + ": " + e.what());
  }
}

const RecipeInput& input_named(const Recipe& recipe, const std::string& name) {
  for (const RecipeInput& in : recipe.inputs)
    if (in.name == name) return in;
  throw InternalError("no input is named \"" + name + "\"");
}

const RecipeOperation& operation_named(const Recipe& recipe, const std::string& name) {
  for (const RecipeOperation& op : recipe.operations)
    if (op.name == name) return op;
  throw InternalError("no operation is named \"" + name + "\"");
}

// The closed mesh an input's level set is converted from, when that is all the input is (one
// closed mesh without a cavity, nothing else): offsets of it are then distances to its own
// triangles (mesh_offsets), made whole, so a slab needs no halo for them.
const TriMesh* lone_closed_mesh(const Plan& plan, const BuiltInputs& inputs, const std::string& name) {
  if (std::find(plan.inputs.begin(), plan.inputs.end(), name) == plan.inputs.end()) return nullptr;
  const GeometrySet& g = inputs.at(name).geometry;
  if (g.solids.size() != 1 || !g.tubes.tubes.empty() || !g.spheres.centers_mm.empty() || !g.shapes.empty() ||
      !g.surfaces.empty() || !g.regions.empty() || !g.cells.empty() || !g.streams.empty())
    return nullptr;
  for (const MeshComponent& c : mesh_components(g.solids[0]))
    if (c.signed_volume_mm3 < 0) return nullptr;
  return &g.solids[0];
}

// The operand an offset, shell or infill distances (an infill's hull); empty for a CSG operation.
std::string distanced_operand(const OperationSpec& op) {
  if (const auto* offset = std::get_if<OffsetOperation>(&op)) return offset->of;
  if (const auto* shell = std::get_if<ShellOperation>(&op)) return shell->of;
  if (const auto* fill = std::get_if<InfillOperation>(&op)) return fill->hull;
  return {};
}

// The operations whose offsets come from an input's own mesh, each with that mesh.
MeshOffsetOperations operations_on_lone_meshes(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs) {
  MeshOffsetOperations out;
  for (const std::string& name : plan.operations) {
    const std::string operand = distanced_operand(operation_named(recipe, name).spec);
    if (operand.empty()) continue;
    if (const TriMesh* mesh = lone_closed_mesh(plan, inputs, operand)) out[name] = mesh;
  }
  return out;
}

std::map<std::string, ObjectExtent> extents_of(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs,
                                               const MeshOffsetOperations& from_mesh);

// The share of a box's height inside the slab's reach (1 without a slab).
double slab_share(const Box3& box, const ZSlab* slab, double band) {
  if (!slab) return 1;
  const double height = box.max.z - box.min.z;
  const double lo = std::max(box.min.z, slab->lo_mm - band), hi = std::min(box.max.z, slab->hi_mm + band);
  if (hi <= lo) return 0;
  return height > 0 ? std::min(1.0, (hi - lo) / height) : 1.0;
}

// The box clipped to the slab's reach, and the slab's two faces across it (mm^2).
Box3 in_slab(Box3 box, const ZSlab* slab, double band, double* faces_mm2) {
  *faces_mm2 = 0;
  if (!slab) return box;
  box.min.z = std::max(box.min.z, slab->lo_mm - band);
  box.max.z = std::min(box.max.z, slab->hi_mm + band);
  if (box.max.z < box.min.z) box.max.z = box.min.z;
  *faces_mm2 = 2 * (box.max.x - box.min.x) * (box.max.y - box.min.y);
  return box;
}

// What voxelizing each planned input needs as a whole (the geometry's area bound and work space).
std::map<std::string, MemoryEstimate> input_estimates(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs,
                                                      const VolumeOptions& vopt) {
  std::map<std::string, MemoryEstimate> out;
  for (const std::string& name : plan.inputs)
    out[name] = in_context(recipe.file + ": " + input_named(recipe, name).json_path,
                           [&] { return estimate_voxelize(inputs.at(name).geometry, vopt); });
  return out;
}

// Memory for everything the plan builds, refused before any large allocation.
MemoryNeed estimate(const Recipe& recipe, const Plan& plan, const std::map<std::string, MemoryEstimate>& input_estimate,
                  const VolumeOptions& vopt, const std::map<std::string, ObjectExtent>& extents,
                  const MeshOffsetOperations& from_mesh, const ZSlab* slab) {
  struct Object {
    double area = 0;
    Box3 box;
    uint64_t voxels = 0;
  };
  const double band = vopt.voxel_size_mm * vopt.half_band_voxels;
  std::map<std::string, Object> objects;
  MemoryNeed total;
  auto mesh_of = [&](uint64_t voxels, double simplify_mm = 0) {
    MemoryEstimate m = estimate_from_voxels(voxels, vopt);
    m.mesh_bytes = uint64_t(double(m.mesh_bytes) * compact_mesh_share(simplify_mm, vopt.voxel_size_mm));
    if (m.mesh_bytes > total.mesh_bytes) {
      total.mesh_bytes = m.mesh_bytes;
      total.triangles = m.triangles;
    }
  };
  for (const std::string& name : plan.inputs) {
    const MemoryEstimate& e = input_estimate.at(name);
    const Box3& whole = extents.at(name).box;
    const double share = slab_share(whole, slab, band);
    double faces = 0;
    const Box3 box = in_slab(whole, slab, band, &faces);
    const double area = e.surface_area_mm2 * share + faces;
    objects[name] = {area, box, band_voxels(area, box, vopt)};
    const uint64_t voxels = slab ? objects[name].voxels : e.active_voxels;
    total.grid_bytes += slab ? estimate_from_voxels(voxels, vopt).grid_bytes : e.grid_bytes;
    total.voxels += voxels;
  }
  for (const std::string& name : plan.operations) {
    const OperationSpec& op = operation_named(recipe, name).spec;
    const std::vector<std::string> of = operands(op);
    Object o;
    const Object& first = objects[of[0]];
    double faces = 0;
    o.box = in_slab(extents.at(name).box, slab, band, &faces);
    const auto* csg = std::get_if<CsgOperation>(&op);
    for (const std::string& operand : of) o.area += objects[operand].area;
    VolumeOptions work = vopt;
    if (!csg) {
      // Goes through the operand's surface mesh and a band as wide as the distance.
      const auto* offset = std::get_if<OffsetOperation>(&op);
      const auto* shell = std::get_if<ShellOperation>(&op);
      double d = offset ? std::fabs(offset->distance_mm) : shell ? shell->thickness_mm : std::get<InfillOperation>(op).skin_mm;
      // Going inwards, nothing is deeper than half the box's smallest side.
      const Vec3d size = extents.at(of[0]).box.size();
      const double half_thickness = 0.5 * std::min({size.x, size.y, size.z});
      if (offset && offset->distance_mm < 0 && d >= half_thickness)
        throw InvalidInput(recipe.file + ": " + operation_named(recipe, name).json_path + ": an offset of " +
                           fixed(offset->distance_mm, 6) + " mm leaves nothing of \"" + of[0] + "\" (it is at most " +
                           fixed(2 * half_thickness, 6) + " mm thick)");
      if (!offset || offset->distance_mm < 0) d = std::min(d, half_thickness);
      // The band grows by the distance on one side only (outwards for a growing offset, inwards
      // otherwise): as much as half of it on each.
      work.half_band_voxels += 0.5 * d / vopt.voxel_size_mm;
      if (from_mesh.count(name)) {
        // Distances to the input's own mesh, over the whole part (in a streamed run, made in the first
        // slab and kept, with its offsets' bands, for the others); no surface is extracted.
        const double area = input_estimate.at(of[0]).surface_area_mm2;
        const Box3& box = extents.at(of[0]).box;
        total.grid_bytes += estimate_from_voxels(band_voxels(area, box, work), work).grid_bytes;
        const uint64_t kept = std::holds_alternative<InfillOperation>(op) ? 2 : 1;
        if (slab) total.grid_bytes += kept * estimate_from_voxels(band_voxels(area, box, vopt), vopt).grid_bytes;
      } else {
        total.mesh_bytes = std::max(total.mesh_bytes, estimate_from_voxels(first.voxels, vopt).surface_bytes);
        // The band as wide as the distance is around the first operand only (an infill's hull).
        MemoryEstimate wide = estimate_from_voxels(band_voxels(first.area, o.box, work), work);
        total.grid_bytes += wide.grid_bytes;
      }
    }
    o.voxels = band_voxels(o.area, o.box, vopt);
    MemoryEstimate e = estimate_from_voxels(o.voxels, vopt);
    total.grid_bytes += e.grid_bytes;
    total.voxels += e.active_voxels;
    objects[name] = o;
  }
  for (const RecipeOutput& out : recipe.outputs)
    if (!out.layers)  // layers are cut from the level set: no mesh
      for (const std::string& name : members(out)) mesh_of(objects[name].voxels, simplify_deviation_mm(recipe, out));
  return total;
}

}  // namespace

std::map<std::string, ObjectExtent> object_extents(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs) {
  return extents_of(recipe, plan, inputs, operations_on_lone_meshes(recipe, plan, inputs));
}

namespace {

std::map<std::string, ObjectExtent> extents_of(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs,
                                               const MeshOffsetOperations& from_mesh) {
  const double h = recipe.voxel_size_mm, band = h * recipe.band_voxels;
  std::map<std::string, ObjectExtent> extents;
  // A rasterized input equals the whole run's a band inside the slab (its faces' band); a level set
  // remade from a surface (offsets, shells, infills) needs its operand right out to the distance it
  // reaches, a band, and the voxel cubes its triangles come from. Offsets of an input's own mesh are
  // made whole and clipped: exact a band inside the slab, which the input's halo already holds.
  for (const std::string& name : plan.inputs) extents[name] = {bounding_box(inputs.at(name).geometry), band + h};
  for (const std::string& name : plan.operations) {
    const OperationSpec& op = operation_named(recipe, name).spec;
    const std::vector<std::string> of = operands(op);
    ObjectExtent e = extents.at(of[0]);
    if (const auto* csg = std::get_if<CsgOperation>(&op)) {
      for (size_t i = 1; i < of.size(); ++i) {
        const ObjectExtent& next = extents.at(of[i]);
        e.halo_mm = std::max(e.halo_mm, next.halo_mm);
        if (csg->kind == CsgOperation::Kind::kUnion) e.box.expand(next.box);
      }
      if (csg->kind == CsgOperation::Kind::kIntersection)
        for (size_t i = 1; i < of.size(); ++i)
          for (int k = 0; k < 3; ++k) {
            e.box.min[k] = std::max(e.box.min[k], extents.at(of[i]).box.min[k]);
            e.box.max[k] = std::max(e.box.min[k], std::min(e.box.max[k], extents.at(of[i]).box.max[k]));
          }
    } else if (const auto* offset = std::get_if<OffsetOperation>(&op)) {
      const double d = offset->distance_mm;
      if (!from_mesh.count(name)) e.halo_mm += std::fabs(d) + band + 3 * h;
      if (d > 0) {
        e.box.min -= Vec3d{d, d, d};
        e.box.max += Vec3d{d, d, d};
      }
    } else if (const auto* shell = std::get_if<ShellOperation>(&op)) {
      if (!from_mesh.count(name)) e.halo_mm += shell->thickness_mm + band + 3 * h;
    } else {
      const auto& fill = std::get<InfillOperation>(op);
      const ObjectExtent& hull = extents.at(fill.hull);
      const double skin_halo = from_mesh.count(name) ? 0 : fill.skin_mm + band + 3 * h;
      e = {hull.box, std::max(extents.at(fill.structure).halo_mm, hull.halo_mm + skin_halo)};
    }
    extents[name] = e;
  }
  return extents;
}

}  // namespace

Volume Evaluation::take(const std::string& name) {
  Volume v = volumes.at(name);
  if (--uses[name] == 0) volumes.erase(name);
  return v;
}

MemoryEstimator::MemoryEstimator(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs)
    : recipe_(recipe),
      plan_(plan),
      from_mesh_(operations_on_lone_meshes(recipe, plan, inputs)),
      extents_(extents_of(recipe, plan, inputs, from_mesh_)),
      inputs_(input_estimates(recipe, plan, inputs, VolumeOptions{recipe.voxel_size_mm, recipe.band_voxels})) {}

MemoryNeed MemoryEstimator::need(const ZSlab* slab) const {
  return estimate(recipe_, plan_, inputs_, VolumeOptions{recipe_.voxel_size_mm, recipe_.band_voxels}, extents_,
                  from_mesh_, slab);
}

uint64_t MemoryEstimator::bytes(const std::vector<ZSlab>& slabs) const {
  if (slabs.empty()) return need().bytes();
  uint64_t most = 0;
  for (const ZSlab& slab : slabs) most = std::max(most, need(&slab).bytes());
  return most;
}

Evaluation evaluate(const Recipe& recipe, const Plan& plan, const BuiltInputs& inputs, const EvaluateOptions& options) {
  ProgressSinkScope progress(options.progress ? options.progress : current_progress_sink());
  ProgressSink* sink = current_progress_sink();
  const VolumeOptions vopt{recipe.voxel_size_mm, recipe.band_voxels};
  Evaluation result;
  result.memory_budget_bytes = options.max_memory_bytes ? options.max_memory_bytes : available_memory_bytes() / 2;
  const uint64_t budget = result.memory_budget_bytes;

  // Refuse what cannot fit before building anything large.
  Box3 extent;
  for (const std::string& name : plan.inputs) {
    const Box3 box = bounding_box(inputs.at(name).geometry);
    // An empty input would vanish from unions and infills without a word.
    if (box.empty())
      throw InvalidInput(recipe.file + ": " + input_named(recipe, name).json_path +
                         ": makes no geometry at all (every piece was dropped or nothing lies in its box)");
    extent.expand(box);
  }
  double reach = 0;
  for (int k = 0; k < 3; ++k) reach = std::max({reach, std::fabs(extent.min[k]), std::fabs(extent.max[k])});
  if (reach / vopt.voxel_size_mm > kMaxCoordinateInVoxels)
    throw ResourceLimit(recipe.file + ": the part reaches " + fixed(reach, 6) + " mm from the origin, more than " +
                        fixed(kMaxCoordinateInVoxels, 6) + " voxels of " + fixed(vopt.voxel_size_mm, 6) +
                        " mm; float32 output cannot keep such a fine surface exact. Move the part nearer the origin "
                        "or use a voxel size of at least " + fixed(reach / kMaxCoordinateInVoxels, 3) + " mm");
  std::optional<MemoryEstimator> own;  // a plan's own, unless the caller made one
  const MemoryEstimator& estimator = options.estimator ? *options.estimator : own.emplace(recipe, plan, inputs);
  const MemoryNeed need = estimator.need(options.slab);
  result.extents = estimator.extents();
  result.memory_estimate_bytes = need.bytes();
  if (need.bytes() > budget)
    throw ResourceLimit(detail::refusal(recipe.file + ": this recipe (about " + fixed(double(need.voxels), 3) +
                                            " voxels and " + fixed(double(need.triangles), 3) + " triangles)",
                                        need.bytes(), budget, vopt));

  // Volumes, built in recipe order and released after their last use.
  result.uses = plan.uses;
  StageTimer timer;
  timer.start("voxelize");
  for (const std::string& name : plan.inputs) {
    throw_if_cancelled(sink);
    result.volumes[name] = in_context(recipe.file + ": " + input_named(recipe, name).json_path,
                                      [&] {
                                        const GeometrySet& geometry = inputs.at(name).geometry;
                                        if (!options.converted_meshes || (geometry.solids.empty() && geometry.regions.empty()))
                                          return voxelize(geometry, vopt, options.slab);
                                        auto [kept, made] = options.converted_meshes->try_emplace(name);
                                        if (made) kept->second = voxelize_meshes(geometry, vopt);
                                        return voxelize(geometry, vopt, options.slab, &kept->second);
                                      });
  }
  timer.start("combine");
  for (const std::string& name : plan.operations) {
    throw_if_cancelled(sink);
    const RecipeOperation& op = operation_named(recipe, name);
    const std::string where = recipe.file + ": " + op.json_path;
    // Offsets of an input's own mesh (whole, made once for every slab of a streamed run), or null.
    const auto mesh_it = estimator.mesh_offset_operations().find(name);
    const TriMesh* mesh = mesh_it == estimator.mesh_offset_operations().end() ? nullptr : mesh_it->second;
    auto offsets_of_mesh = [&](const std::vector<double>& distances_mm) {
      std::vector<Volume> whole;
      if (options.slab && options.mesh_offsets) {
        auto [kept, made] = options.mesh_offsets->try_emplace(name);
        if (made) kept->second = mesh_offsets(*mesh, vopt, distances_mm);
        whole = kept->second;
      } else {
        whole = mesh_offsets(*mesh, vopt, distances_mm);
      }
      if (options.slab)
        for (Volume& w : whole) w = clip_to_slab(w, *options.slab);
      return whole;
    };
    Volume v;
    if (const auto* csg = std::get_if<CsgOperation>(&op.spec)) {
      v = result.take(csg->of[0]);
      for (size_t i = 1; i < csg->of.size(); ++i) {
        const Volume next = result.take(csg->of[i]);
        switch (csg->kind) {
          case CsgOperation::Kind::kUnion: v = unite(v, next); break;
          case CsgOperation::Kind::kDifference: v = subtract(v, next); break;
          case CsgOperation::Kind::kIntersection: v = intersect(v, next); break;
        }
      }
    } else if (const auto* offset = std::get_if<OffsetOperation>(&op.spec)) {
      v = result.take(offset->of);
      if (mesh && offset->distance_mm != 0) {
        v = offsets_of_mesh({offset->distance_mm}).front();
      } else {
        detail::require_surface_memory(v, budget, where, vopt);
        v = lacuna::offset(v, offset->distance_mm);
      }
    } else if (const auto* shell = std::get_if<ShellOperation>(&op.spec)) {
      v = result.take(shell->of);
      if (mesh) {
        v = lacuna::shell(v, shell->thickness_mm, offsets_of_mesh({-shell->thickness_mm}).front());
      } else {
        detail::require_surface_memory(v, budget, where, vopt);
        v = lacuna::shell(v, shell->thickness_mm);
      }
    } else {
      const auto& fill = std::get<InfillOperation>(op.spec);
      Volume hull = result.take(fill.hull), structure = result.take(fill.structure);
      if (!mesh) detail::require_surface_memory(hull, budget, where, vopt);
      // Fused by a voxel unless told otherwise (and never through the whole skin).
      double fuse = fill.fuse_mm >= 0 ? fill.fuse_mm : std::min(vopt.voxel_size_mm, 0.5 * fill.skin_mm);
      v = in_context(where, [&] {
        return mesh ? infill(hull, structure, offsets_of_mesh(infill_offsets(fill.skin_mm, fuse)))
                    : infill(hull, structure, fill.skin_mm, fuse);
      });
      result.hull_volume_mm3[op.name] = hull.voxel_volume_mm3();
    }
    result.volumes[op.name] = v;
  }
  timer.stop();
  result.stage_seconds = timer.seconds();
  return result;
}

}  // namespace lacuna
