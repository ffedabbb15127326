#include "pipeline/report.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "export/report.h"

namespace lacuna {
namespace {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

nlohmann::json features_json(const std::vector<PrintFeature>& features) {
  nlohmann::json list = nlohmann::json::array();
  for (const PrintFeature& f : features)
    list.push_back({{"volume_mm3", f.volume_mm3}, {"location", {f.location_mm.x, f.location_mm.y, f.location_mm.z}}});
  return list;
}

nlohmann::json printability_json(const PrintabilityFindings& p) {
  return {{"trapped_voids", features_json(p.trapped_voids)},
          {"thin_walls", features_json(p.thin_walls)},
          {"small_holes", features_json(p.small_holes)},
          {"overhang_area_mm2", p.overhang_area_mm2},
          {"down_facing_area_mm2", p.down_facing_area_mm2},
          {"drain_holes", p.drain_holes},
          {"thickened_walls", p.thickened_walls},
          {"loose_pieces", features_json(p.loose_pieces)},
          {"loose_pieces_removed", p.loose_pieces_removed},
          {"loose_volume_removed_mm3", p.loose_volume_removed_mm3}};
}

// The object's printability findings and relative density, added to an output's entry.
void annotate(nlohmann::json& entry, const OutputReport& out) {
  if (out.printability) {
    entry["printability"] = printability_json(*out.printability);
    for (const std::string& p : out.printability->problems) {
      entry["checks"]["problems"].push_back(p);
      entry["checks"]["valid"] = false;
    }
  }
  if (out.hull_volume_mm3 && *out.hull_volume_mm3 > 0 && entry.contains("volume_mm3"))
    entry["relative_density"] = entry["volume_mm3"].get<double>() / *out.hull_volume_mm3;
}

}  // namespace

bool OutputReport::valid() const {
  if (printability && !printability->problems.empty()) return false;
  if (layers) return layers->problems.empty();
  if (tetrahedra) return tetrahedra->valid();
  return check && check->valid() && objects == group;
}

nlohmann::json to_json(const InputReport& report) {
  return std::visit(
      Overloaded{
          [](const std::monostate&) { return nlohmann::json(); },
          [](const CurveReport& r) { return nlohmann::json{{"tubes", r.tubes}, {"segments", r.segments}}; },
          [](const MotifFillReport& r) {
            nlohmann::json j = {{"motifs", r.motifs}, {"fill_fraction", r.fill_fraction}, {"stop_reason", r.stop_reason}};
            if (r.fundamental_region_motifs) j["fundamental_region_motifs"] = *r.fundamental_region_motifs;
            return j;
          },
          [](const VolumeFillReport& r) {
            return nlohmann::json{{r.polyhedra ? "polyhedra" : "spheres", r.placed},
                                  {"fill_fraction", r.fill_fraction},
                                  {"stop_reason", r.stop_reason}};
          },
          [](const VoronoiSpheresReport& r) { return nlohmann::json{{"points", r.points}, {"spheres", r.spheres}}; },
          [](const VoronoiWallsReport& r) {
            nlohmann::json j = {{"points", r.points},
                                {"boundary_generators", r.boundary_generators},
                                {"wall_facets", r.wall_facets},
                                {r.dimension == 2 ? "wall_length_mm" : "wall_area_mm2", r.wall_measure}};
            if (r.pieces) j["pieces"] = *r.pieces;
            if (r.clearance_mm) j["clearance_mm"] = *r.clearance_mm;
            if (!r.tiles_per_level.empty()) j["tiles_per_level"] = r.tiles_per_level;
            return j;
          },
          [](const BcifsPlateReport& r) {
            nlohmann::json faces = nlohmann::json::array();
            for (const BcifsFaceReport& f : r.faces)
              faces.push_back({{"type", f.type}, {"subfaces", f.subfaces}, {"lacunas", f.lacunas}, {"r_limit", f.r_limit}});
            return nlohmann::json{{"level", r.level}, {"face_types", r.face_types}, {"faces", faces},
                                  {"loops", r.loops},  {"holes", r.holes},           {"area_mm2", r.area_mm2}};
          },
          [](const BcifsCellReport& r) {
            return nlohmann::json{{"faces", r.faces}, {"face_types", r.face_types}, {"holes", r.holes},
                                  {"face_area_mm2", r.face_area_mm2}};
          },
          [](const BcifsVolumeReport& r) {
            nlohmann::json j{{"level", r.level},           {"cells", r.cells},
                                  {"lacunas", r.lacunas},       {"r_limit", r.r_limit},
                                  {"cell_types", r.cell_types}, {"face_types", r.face_types},
                                  {"shared_faces", r.shared_faces}, {"pieces", r.pieces},
                                  {"volume_mm3", r.volume_mm3}};
            if (r.tetrahedra) {
              j["tetrahedra"] = r.tetrahedra;
              j["cell_mm"] = {r.min_cell_mm, r.max_cell_mm};
              j["max_delay"] = r.max_delay;
              j["lacuna_mm"] = {r.min_lacuna_mm, r.max_lacuna_mm};
              j["lacuna_scale"] = {r.min_lacuna_scale, r.max_lacuna_scale};
              j["levels"] = {r.min_level, r.max_level};
            }
            return j;
          },
      },
      report);
}

nlohmann::json to_json(const OutputReport& out) {
  nlohmann::json entry;
  if (out.layers) {
    const LayerOutputReport& l = *out.layers;
    entry = {{"file", out.file},
             {"format", out.format},
             {"object", out.object},
             {"layers", {{"count", l.layers},
                         {"layer_mm", l.layer_mm},
                         {"pixel_mm", l.pixel_mm},
                         {"tolerance_mm", l.tolerance_mm},
                         {"z0_mm", l.z0_mm},
                         {"width", l.width},
                         {"height", l.height},
                         {"contours", l.contours},
                         {"max_area_difference_mm2", l.max_area_difference_mm2},
                         {"bytes", l.bytes}}},
             {"checks", {{"valid", l.problems.empty()}, {"problems", l.problems}}},
             {"voxels", out.voxels}};
    annotate(entry, out);
    return entry;
  }
  if (out.tetrahedra) {
    entry = fea_report_json(*out.tetrahedra);
    entry["file"] = out.file;
    entry["format"] = out.format;
    entry["object"] = out.object;
  } else {
    entry = check_report_json(out.check ? *out.check : MeshCheckReport{});
    entry["file"] = out.file;
    entry["format"] = out.format;
    entry["object"] = out.object;
    if (!out.group.empty()) {
      // The package as written holds every object once, in order; together they are checked as one
      // solid, so they are also free of intersections with each other.
      entry["objects"] = out.objects;
      if (out.objects != out.group) {
        entry["checks"]["valid"] = false;
        entry["checks"]["objects_as_asked"] = false;
      }
    }
    entry["part_name"] = out.part_name;
  }
  entry["voxels"] = out.voxels;
  entry["subvoxel_cavities_filled"] = out.subvoxel_cavities_filled;
  entry["subvoxel_specks_removed"] = out.subvoxel_specks_removed;
  entry["simplify_mm"] = out.simplify_mm;
  entry["extracted_triangles"] = out.extracted_triangles;
  if (out.draco) entry["draco"] = to_json(*out.draco);
  if (!out.picture.empty()) entry["picture"] = out.picture;
  annotate(entry, out);
  return entry;
}

nlohmann::json to_json(const DracoFigures& d) {
  return {{"quantization_bits", d.quantization_bits},
          {"max_move_mm", d.max_move_mm},
          {"file_bytes", d.file_bytes},
          {"binary_stl_bytes", d.binary_stl_bytes},
          {"compression_vs_binary_stl", double(d.binary_stl_bytes) / double(std::max<uint64_t>(d.file_bytes, 1))},
          {"refinements", d.refinements}};
}

nlohmann::json to_json(const RunReport& report) {
  nlohmann::json outputs = nlohmann::json::array();
  for (const OutputReport& out : report.outputs) outputs.push_back(to_json(out));
  nlohmann::json stages = nlohmann::json::object();
  double total = 0;
  for (const auto& s : report.stage_seconds) {
    stages[s.first] = s.second;
    total += s.second;
  }
  nlohmann::json j = {
      {"lacuna_version", report.lacuna_version},
      {"recipe", report.recipe},
      {"name", report.name},
      {"voxel_size_mm", report.voxel_size_mm},
      {"band_voxels", report.band_voxels},
      {"seed", report.seed},
      {"valid", report.valid},
      {"outputs", outputs},
      {"stage_seconds", stages},
      {"total_seconds", total},
      {"peak_memory_bytes", report.peak_memory_bytes},
      {"peak_memory_children_bytes", report.peak_memory_children_bytes},
      {"memory_estimate_bytes", report.memory_estimate_bytes},
      {"memory_budget_bytes", report.memory_budget_bytes},
      {"threads", report.threads},
  };
  nlohmann::json inputs = nlohmann::json::object();
  for (const auto& [name, input] : report.inputs)
    if (!std::holds_alternative<std::monostate>(input)) inputs[name] = to_json(input);
  if (!inputs.empty()) j["inputs"] = inputs;
  return j;
}

}  // namespace lacuna
