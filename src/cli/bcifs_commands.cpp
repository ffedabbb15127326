#include "cli/bcifs_commands.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bcifs/realize.h"
#include "bcifs/plate.h"
#include "bcifs/topology.h"
#include "cli/exit_codes.h"
#include "errors.h"
#include "pipeline/build_inputs.h"
#include "pipeline/generators.h"
#include "pipeline/input_figures.h"
#include "recipe/input_parsers.h"
#include "recipe/json_fields.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

struct BcifsArgs {
  std::string boundary;
  std::string params = "C2 B2 B2";
  std::string algorithm = "A1";
  int delay = 1;
  std::string recipe;
  std::string levels = "0..4";
  std::string out_dir;
  int mask_px = 31;
  bool json = false;
};

int bcifs_rules(const BcifsArgs& a) {
  bcifs::FaceType face;
  face.boundary = bcifs::parse_boundary(a.boundary);
  face.edges = bcifs::parse_edge_set(a.params);
  face.algorithm = bcifs::parse_algorithm(a.algorithm);
  face.delay = a.delay;
  const bcifs::RuleSet rules = bcifs::build_rules(face);
  const nlohmann::json j = bcifs::rules_json(rules, rules.roots[0]);
  if (a.json) {
    std::cout << j.dump(1) << "\n";
    return kExitOk;
  }
  for (const auto& t : j["face_types"]) {
    std::string boundary, children;
    for (const auto& e : t["boundary"]) boundary += (boundary.empty() ? "" : " ") + e.get<std::string>();
    for (const auto& c : t["children"]) children += (children.empty() ? "" : " ") + std::to_string(c.get<int>());
    std::printf("type %d: <%s> delay %d %s -> %s  (lacunas at level 1: %g)\n", t["id"].get<int>(), boundary.c_str(),
                t["delay"].get<int>(), t["algorithm"].get<std::string>().c_str(), children.c_str(),
                t["lacunas_1"].get<double>());
  }
  std::printf("root %d: N^L_1 = %g, N^C_1 = %g, R = %.12g (spectral radius %.6g)\n", j["root"].get<int>(),
              j["lacunas_1"].get<double>(), j["subfaces_1"].get<double>(), j["r_limit"].get<double>(),
              j["spectral_radius"].get<double>());
  return kExitOk;
}

// "A..B" or "B" (meaning 0..B).
std::pair<int, int> parse_levels(const std::string& text) {
  int lo = 0, hi = 0;
  char dots[3] = {0, 0, 0};
  std::istringstream in(text);
  if (text.find("..") != std::string::npos) {
    if (!(in >> lo >> dots[0] >> dots[1] >> hi) || dots[0] != '.' || dots[1] != '.')
      throw InvalidInput("--levels: expected \"A..B\" such as 0..5, got \"" + text + "\"");
  } else if (!(in >> hi)) {
    throw InvalidInput("--levels: expected \"A..B\" such as 0..5, got \"" + text + "\"");
  }
  if (lo < 0 || hi < lo || hi > kMaxTopologyLevel || lo > kMaxGeometryLevel)
    throw InvalidInput("--levels: expected 0 <= A <= B <= 12 and A <= 8 (areas and box counting to 8, counts to 12), got \"" +
                       text + "\"");
  return {lo, hi};
}

int bcifs_measure(const BcifsArgs& a) {
  const auto [lo, hi] = parse_levels(a.levels);
  const nlohmann::json top = read_json_file(a.recipe, "a recipe file (.json)");
  if (!top.is_object() || !top.contains("inputs") || !top["inputs"].is_object())
    throw InvalidInput(a.recipe + ": expected a recipe with \"inputs\"");
  const fs::path out_dir = a.out_dir.empty() ? fs::path(fs::path(a.recipe).stem().string() + "_measures") : fs::path(a.out_dir);
  nlohmann::json result = nlohmann::json::object();
  std::vector<std::pair<std::string, std::vector<uint8_t>>> images;  // written only once everything worked
  for (const auto& [name, value] : top["inputs"].items()) {
    if (value.is_object() && value.value("type", "") == "bcifs_volume") {
      nlohmann::json object = value;
      object.erase("type");
      const std::string path = "inputs." + name;
      const BcifsVolumeInput input = parse_bcifs_volume_input(JsonObject(object, a.recipe, path));
      VolumeCellMeasures m;
      try {
        m = measure_volume(input.spec, input.options, hi);
      } catch (const InvalidInput& e) {
        throw InvalidInput(a.recipe + ": " + path + ": " + e.what());
      } catch (const ResourceLimit& e) {
        throw ResourceLimit(a.recipe + ": " + path + ": " + e.what());
      }
      nlohmann::json cells = nlohmann::json::array();
      for (size_t c = 0; c < m.cells.size(); ++c) {
        const bcifs::Lacunarity& l = m.cells[c];
        cells.push_back({{"type", m.cell_types[c]}, {"cells", l.subfaces}, {"lacunas", l.lacunas}, {"ratio", l.ratio},
                         {"r_limit", l.limit}, {"spectral_radius", l.spectral_radius}});
      }
      const bcifs::VolumeMeasures& g = m.geometry;
      result[name] = {{"kind", "volume"},
                      {"topology", cells},
                      {"cell_types", m.cell_type_count},
                      {"face_types", m.face_type_count},
                      {"levels", {0, hi}},
                      {"geometry_levels", {0, m.geometry_last}},
                      {"volume_mm3", g.volume},
                      {"surface_mm2", g.surface},
                      {"F_V", g.volume_factor},
                      {"F_S", g.surface_factor},
                      {"tunnels", g.tunnels},
                      {"genus", g.genus},
                      {"box_counting",
                       {{"grid", kVolumeBoxGrid},
                        {"fill", m.grid_fill},
                        {"region_dimension", m.region.dimension},
                        {"boundary_dimension", m.boundary.dimension},
                        {"log_inverse_size", m.region.log_inverse_size},
                        {"region_log_count", m.region.log_count},
                        {"boundary_log_count", m.boundary.log_count}}}};
      VolumeImages drawn = volume_images(m, a.mask_px);
      nlohmann::json sections = nlohmann::json::array();
      for (size_t axis = 0; axis < 3; ++axis) {
        const std::string file = (out_dir / (name + "_section_" + "xyz"[axis] + ".png")).string();
        double fill = 0;
        for (uint8_t v : m.sections[axis]) fill += v;
        fill /= double(m.sections[axis].size());
        sections.push_back({{"axis", std::string(1, "xyz"[axis])},
                            {"at_mm", m.section_mm[axis]},
                            {"fill", fill},
                            {"density_map", file}});
        images.push_back({file, std::move(drawn.section_png[axis])});
      }
      const std::string plot_file = (out_dir / (name + "_plot.png")).string();
      images.push_back({plot_file, std::move(drawn.plot_png)});
      result[name]["sections"] = sections;
      result[name]["mask_px"] = a.mask_px;
      result[name]["plot"] = plot_file;
      continue;
    }
    if (!value.is_object() || value.value("type", "") != "bcifs_plate") continue;
    nlohmann::json object = value;
    object.erase("type");
    const std::string path = "inputs." + name;
    const bcifs::Plate plate = build_plate(parse_bcifs_plate_input(JsonObject(object, a.recipe, path)), a.recipe, path);
    const PlateMeasures measures = measure_plate(plate, lo, hi);
    nlohmann::json entry;
    nlohmann::json faces = nlohmann::json::array();
    for (size_t f = 0; f < measures.faces.size(); ++f) {
      const bcifs::Lacunarity& l = measures.faces[f];
      faces.push_back({{"type", measures.face_types[f]}, {"subfaces", l.subfaces}, {"lacunas", l.lacunas},
                       {"ratio", l.ratio}, {"r_limit", l.limit}, {"spectral_radius", l.spectral_radius}});
    }
    entry["topology"] = faces;
    const bcifs::GeometricMeasures& m = measures.geometry;
    const bcifs::BoxCount& region = measures.region;
    const bcifs::BoxCount& boundary = measures.boundary;
    entry["levels"] = {lo, hi};
    entry["geometry_levels"] = {lo, std::min(hi, kMaxGeometryLevel)};
    entry["area_mm2"] = m.area;
    entry["perimeter_mm"] = m.perimeter;
    entry["F_A"] = m.area_factor;
    entry["F_P"] = m.perimeter_factor;
    entry["box_counting"] = {{"region_dimension", region.dimension},
                             {"boundary_dimension", boundary.dimension},
                             {"log_inverse_size", boundary.log_inverse_size},
                             {"boundary_log_count", boundary.log_count},
                             {"region_log_count", region.log_count}};
    PlateImages drawn = plate_images(measures, a.mask_px);
    const std::string density_file = (out_dir / (name + "_density.png")).string();
    const std::string plot_file = (out_dir / (name + "_plot.png")).string();
    images.push_back({density_file, std::move(drawn.density_png)});
    images.push_back({plot_file, std::move(drawn.plot_png)});
    entry["density_map"] = density_file;
    entry["mask_px"] = a.mask_px;
    entry["plot"] = plot_file;
    result[name] = entry;
  }
  if (result.empty())
    throw InvalidInput(a.recipe + ": inputs: no input of type \"bcifs_plate\" or \"bcifs_volume\" to measure");
  if (!images.empty()) fs::create_directories(out_dir);
  for (const auto& [path, bytes] : images) {
    const std::string temp = path + ".part";
    std::ofstream out(temp, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    out.close();
    if (!out) {
      std::remove(temp.c_str());
      throw IoError(path + ": cannot write");
    }
    fs::rename(temp, path);
  }
  if (a.json) {
    std::cout << result.dump(1) << "\n";
    return kExitOk;
  }
  for (const auto& [name, e] : result.items()) {
    std::printf("%s:\n", name.c_str());
    if (e.value("kind", "") == "volume") {
      for (size_t i = 0; i < e["volume_mm3"].size(); ++i)
        std::printf("  level %zu: volume %.6g mm3, surface %.6g mm2, tunnels %g, genus %g\n", i,
                    e["volume_mm3"][i].get<double>(), e["surface_mm2"][i].get<double>(), e["tunnels"][i].get<double>(),
                    e["genus"][i].get<double>());
      std::printf("  F_V %.6g, F_S %.6g (levels 0..%d); %d cell types, %d face types\n", e["F_V"].get<double>(),
                  e["F_S"].get<double>(), e["geometry_levels"][1].get<int>(), e["cell_types"].get<int>(),
                  e["face_types"].get<int>());
      for (const auto& c : e["topology"])
        std::printf("  cell type %d: N^C %g, N^L %g, R_%d %.6g, R %.9g\n", c["type"].get<int>(),
                    c["cells"].back().get<double>(), c["lacunas"].back().get<double>(), hi,
                    c["ratio"].back().get<double>(), c["r_limit"].get<double>());
      const nlohmann::json& boxes = e["box_counting"];
      std::printf("  level %d on a %d^3 grid: fill %.4g, box-counting dimension %.4g (solid), %.4g (boundary)\n",
                  e["geometry_levels"][1].get<int>(), boxes["grid"].get<int>(), boxes["fill"].get<double>(),
                  boxes["region_dimension"].get<double>(), boxes["boundary_dimension"].get<double>());
      for (const auto& c : e["sections"])
        std::printf("  section %s = %.6g mm: fill %.4g, wrote %s\n", c["axis"].get<std::string>().c_str(),
                    c["at_mm"].get<double>(), c["fill"].get<double>(), c["density_map"].get<std::string>().c_str());
      std::printf("  wrote %s\n", e["plot"].get<std::string>().c_str());
      continue;
    }
    for (size_t i = 0; i < e["area_mm2"].size(); ++i)
      std::printf("  level %d: area %.6g mm2, perimeter %.6g mm\n", lo + int(i), e["area_mm2"][i].get<double>(),
                  e["perimeter_mm"][i].get<double>());
    std::printf("  F_A %.6g, F_P %.6g, box-counting dimension %.4g (region), %.4g (boundary)\n", e["F_A"].get<double>(),
                e["F_P"].get<double>(), e["box_counting"]["region_dimension"].get<double>(),
                e["box_counting"]["boundary_dimension"].get<double>());
    for (const auto& f : e["topology"])
      std::printf("  face type %d: N^C %g, N^L %g, R_%d %.6g, R %.9g\n", f["type"].get<int>(),
                  f["subfaces"].back().get<double>(), f["lacunas"].back().get<double>(), hi, f["ratio"].back().get<double>(),
                  f["r_limit"].get<double>());
    std::printf("  wrote %s and %s\n", e["density_map"].get<std::string>().c_str(), e["plot"].get<std::string>().c_str());
  }
  return kExitOk;
}

}  // namespace

std::function<int()> add_bcifs_commands(CLI::App& app) {
  auto args = std::make_shared<BcifsArgs>();
  CLI::App* bcifs = app.add_subcommand("bcifs", "Lacunar faces (boundary-controlled IFS): rule sets and measures");
  bcifs->require_subcommand(1);
  CLI::App* rules = bcifs->add_subcommand("rules", "The rule set of a face: face types, sub-faces, N^L_1, N^C_1, R");
  rules->add_option("--boundary", args->boundary, "Edge types counter-clockwise, e.g. \"C4 B2 C2 B2 C3 B2\"")->required();
  rules->add_option("--params", args->params, "E = \"Ea El Ec\" (default \"C2 B2 B2\")");
  rules->add_option("--algorithm", args->algorithm, "A1 (default), A2 or A3");
  rules->add_option("--delay", args->delay, "Delay of the face (1: none)")->check(CLI::Range(1, 16));
  rules->add_flag("--json", args->json, "Print JSON");
  CLI::App* measure = bcifs->add_subcommand(
      "measure",
      "Topological and geometric measures of the bcifs_plate inputs of a recipe, with density maps and plots, and of "
      "its bcifs_volume inputs (cells, lacunas, volumes, surfaces, tunnels, genus)");
  measure->add_option("recipe", args->recipe, "Recipe file")->required();
  measure->add_option("--levels", args->levels,
                      "Levels A..B (default 0..4): the counts N^C, N^L, R from 0 to B (at most 12), areas, perimeters "
                      "and box counting from A to B (at most 8)");
  measure->add_option("-o,--output", args->out_dir, "Folder for the PNG files (default: <recipe>_measures)");
  measure->add_option("--mask-px", args->mask_px, "Side of the density mask in pixels (of 1024)")->check(CLI::Range(1, 1023));
  measure->add_flag("--json", args->json, "Print JSON");
  return [=]() -> int {
    if (*rules) return bcifs_rules(*args);
    if (*measure) return bcifs_measure(*args);
    return -1;
  };
}

}  // namespace lacuna
