#include "cli/cifs_commands.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "cifs/library.h"
#include "cifs/nurbs.h"
#include "cli/exit_codes.h"
#include "errors.h"
#include "pipeline/generators.h"
#include "recipe/cifs_system.h"
#include "recipe/json_fields.h"

namespace lacuna {
namespace {

struct CifsArgs {
  std::string system;
  int level = 3;
  std::string format = "json";
  bool json = false;
};

struct NurbsArgs {
  int degree = 2;
  std::string knots;
  std::string control_points;
  int level = 4;
  bool json = false;
};

std::vector<double> parse_knots(const std::string& text) {
  std::vector<double> knots;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      double v = std::stod(item, &used);
      if (used != item.size() && item.find_first_not_of(" ", used) != std::string::npos) throw std::invalid_argument(item);
      if (!std::isfinite(v)) throw std::invalid_argument(item);
      knots.push_back(v);
    } catch (const std::exception&) {
      throw InvalidInput("--knots: \"" + item + "\" is not a number (expected t0,t1,...)");
    }
  }
  return knots;
}

nlohmann::json point_json(const Vec3d& p) { return {p.x, p.y, p.z}; }

int cifs_info(const CifsArgs& args) {
  cifs::Cifs c = cifs::load_system(args.system);
  cifs::complete_primitives(c.automaton);
  nlohmann::json j = cifs::system_json(c);
  if (args.json) {
    std::cout << j.dump(2) << "\n";
    return kExitOk;
  }
  std::printf("%s: %zu state%s, alphabet of %d, initial state %d%s\n", c.name.c_str(), c.automaton.states.size(),
              c.automaton.states.size() == 1 ? "" : "s", c.automaton.alphabet_size, c.automaton.initial,
              c.rational ? ", rational" : "");
  for (const auto& s : j["states"]) {
    std::printf("  state %d %s: %d control points, %s%s\n", s["index"].get<int>(), s["name"].get<std::string>().c_str(),
                s["control_points"].get<int>(), s["primitive"].get<std::string>().c_str(),
                s["stationary"].get<bool>() ? ", stationary" : "");
    for (const auto& f : s["fixed_points"]) std::printf("    fixed point of symbol %d: %s\n", f["symbol"].get<int>(), f["barycentric"].dump().c_str());
  }
  for (const auto& f : j["limit_frames"]) {
    std::printf("  limit of symbol %d^w at %s: ", f["symbol"].get<int>(), f.value("point_mm", nlohmann::json()).dump().c_str());
    if (!f["smooth"].get<bool>()) std::printf("not smooth (%s)\n", f["reason"].get<std::string>().c_str());
    else if (f.contains("normal")) std::printf("tangents %s, normal %s\n", f["tangents"].dump().c_str(), f["normal"].dump().c_str());
    else std::printf("tangent %s\n", f["tangents"][0].dump().c_str());
  }
  for (const auto& t : j["transitions"])
    std::printf("  %d --%d--> %d\n", t["from"].get<int>(), t["symbol"].get<int>(), t["to"].get<int>());
  return kExitOk;
}

int cifs_tessellate(const CifsArgs& args) {
  if (args.format != "json" && args.format != "csv" && args.format != "obj")
    throw InvalidInput("--format: expected json, csv or obj, got \"" + args.format + "\"");
  const cifs::Cifs c = cifs::load_system(args.system);
  const CifsTessellation t = tessellate_system(c, args.level);
  const int dimension = t.dimension;
  const uint64_t pieces = t.pieces;
  const std::vector<Vec3d>& points = t.points_mm;
  const std::vector<std::vector<uint32_t>>& cells = t.cells;  // polylines, triangles or cells as vertex lists
  const std::vector<std::vector<uint32_t>>& faces = t.faces;  // for obj: the faces of the cells
  if (args.format == "json") {
    nlohmann::json j = {{"system", c.name}, {"level", args.level}, {"pieces", pieces}, {"points", nlohmann::json::array()}};
    for (const Vec3d& p : points) j["points"].push_back(point_json(p));
    const char* key = dimension == 1 ? "polylines" : dimension == 2 ? "triangles" : "cells";
    j[key] = cells;
    std::cout << j.dump() << "\n";
  } else if (args.format == "csv") {
    std::cout << "x,y,z\n";
    char line[128];
    for (const Vec3d& p : points) {
      std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g\n", p.x, p.y, p.z);
      std::cout << line;
    }
  } else {
    char line[128];
    for (const Vec3d& p : points) {
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", p.x, p.y, p.z);
      std::cout << line;
    }
    for (const auto& cell : dimension == 3 ? faces : cells) {
      std::cout << (dimension == 1 ? "l" : "f");
      for (uint32_t id : cell) std::cout << " " << id + 1;
      std::cout << "\n";
    }
  }
  return kExitOk;
}

nlohmann::json matrix_json(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

int nurbs_automaton_command(const NurbsArgs& args) {
  cifs::NurbsAutomaton na = cifs::nurbs_automaton(args.degree, parse_knots(args.knots));
  std::vector<int> stationary = cifs::stationary_states(na.automaton);
  nlohmann::json states = nlohmann::json::array();
  for (size_t q = 0; q < na.windows.size(); ++q) {
    nlohmann::json transitions = nlohmann::json::object();
    for (const cifs::Transition& t : na.automaton.transitions[q])
      transitions[t.symbol == 0 ? "L" : "R"] = {{"to", t.target}, {"matrix", matrix_json(t.matrix)}};
    states.push_back({{"index", q},
                      {"window", na.windows[q]},
                      {"stationary", std::find(stationary.begin(), stationary.end(), int(q)) != stationary.end()},
                      {"transitions", transitions}});
  }
  if (args.json) {
    std::cout << nlohmann::json{{"degree", args.degree}, {"states", states}}.dump(2) << "\n";
    return kExitOk;
  }
  std::printf("degree %d: %zu states, %zu stationary\n", args.degree, na.windows.size(), stationary.size());
  for (const auto& s : states)
    std::printf("  state %d window %s%s: L -> %d, R -> %d\n", s["index"].get<int>(), s["window"].dump().c_str(),
                s["stationary"].get<bool>() ? " (stationary)" : "", s["transitions"]["L"]["to"].get<int>(),
                s["transitions"]["R"]["to"].get<int>());
  return kExitOk;
}

int nurbs_tessellate_command(const NurbsArgs& args) {
  std::vector<double> knots = parse_knots(args.knots);
  const nlohmann::json points = read_json_file(args.control_points, "a control points file (.json)");
  const NurbsCurvePoints curve = nurbs_curve_points(args.degree, knots, points, args.level, args.control_points);
  nlohmann::json out = {{"degree", args.degree}, {"level", args.level}, {"points", nlohmann::json::array()},
                        {"parameters", curve.parameters}};
  for (const Vec3d& p : curve.points_mm) out["points"].push_back(point_json(p));
  if (!curve.tangents.empty()) {
    out["tangents"] = nlohmann::json::array();
    for (const Vec3d& t : curve.tangents) out["tangents"].push_back(point_json(t));
  }
  if (args.json) {
    std::cout << out.dump() << "\n";
  } else {
    char line[160];
    for (size_t k = 0; k < out["points"].size(); ++k) {
      std::snprintf(line, sizeof line, "%.17g %.17g %.17g %.17g\n", out["parameters"][k].get<double>(),
                    out["points"][k][0].get<double>(), out["points"][k][1].get<double>(), out["points"][k][2].get<double>());
      std::cout << line;
    }
  }
  return kExitOk;
}

}  // namespace

std::function<int()> add_cifs_commands(CLI::App& app) {
  auto cifs_args = std::make_shared<CifsArgs>();
  auto nurbs_args = std::make_shared<NurbsArgs>();
  CLI::App* cifs = app.add_subcommand("cifs", "Inspect controlled iterated function systems (CIFS)");
  cifs->require_subcommand(1);
  CLI::App* info = cifs->add_subcommand("info", "States, transitions, stationary states and fixed points of a system");
  info->add_option("SYSTEM", cifs_args->system, "A system file (JSON) or a shipped system's name")->required();
  info->add_flag("--json", cifs_args->json, "Print JSON");
  CLI::App* tess = cifs->add_subcommand("tessellate", "The vertices of a system's tessellation at a level");
  tess->add_option("SYSTEM", cifs_args->system, "A system file (JSON) or a shipped system's name")->required();
  tess->add_option("--level", cifs_args->level, "Subdivision level (number of maps applied)")->check(CLI::Range(0, 24));
  tess->add_option("--format", cifs_args->format, "json (points and pieces), csv (x,y,z) or obj");

  CLI::App* nurbs = app.add_subcommand("nurbs", "NURBS curves as CIFS automata");
  nurbs->require_subcommand(1);
  CLI::App* automaton = nurbs->add_subcommand("automaton", "The automaton of one B-spline piece: states (inter-node windows) and matrices");
  CLI::App* ntess = nurbs->add_subcommand("tessellate", "The points of one NURBS piece at a level (2^level + 1 points)");
  for (CLI::App* sub : {automaton, ntess}) {
    sub->add_option("--degree", nurbs_args->degree, "Degree d >= 1")->required()->check(CLI::Range(1, 12));
    sub->add_option("--knots", nurbs_args->knots, "The 2d knots t0,t1,...,t(2d-1) of the piece")->required();
    sub->add_flag("--json", nurbs_args->json, "Print JSON");
  }
  ntess->add_option("--control-points", nurbs_args->control_points,
                    "JSON file: a list of d + 1 points [x, y, z] (mm), or [x, y, z, w] for a rational curve")
      ->required();
  ntess->add_option("--level", nurbs_args->level, "Subdivision level")->check(CLI::Range(0, 24));

  return [=]() -> int {
    if (*info) return cifs_info(*cifs_args);
    if (*tess) return cifs_tessellate(*cifs_args);
    if (*automaton) return nurbs_automaton_command(*nurbs_args);
    if (*ntess) return nurbs_tessellate_command(*nurbs_args);
    return -1;
  };
}

}  // namespace lacuna
