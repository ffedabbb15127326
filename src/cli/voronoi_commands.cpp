#include "cli/voronoi_commands.h"

#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/exit_codes.h"
#include "errors.h"
#include "pipeline/generators.h"
#include "voronoi/rules.h"
#include "voronoi/walls.h"

namespace lacuna {
namespace {

struct VoronoiArgs {
  int dimension = 2;
  int d = 2;
  std::string points;
  int random = 0;
  uint64_t seed = 1;
  int level = 2;
  std::string children = "scaled";
  bool json = false;
};

// "x,y;x,y;..." (or x,y,z in 3D).
std::vector<std::vector<double>> parse_points(const std::string& text, int n) {
  std::vector<std::vector<double>> points;
  std::stringstream all(text);
  std::string item;
  while (std::getline(all, item, ';')) {
    std::vector<double> p;
    std::stringstream coords(item);
    std::string c;
    while (std::getline(coords, c, ',')) {
      try {
        size_t used = 0;
        p.push_back(std::stod(c, &used));
        if (c.find_first_not_of(" ", used) != std::string::npos) throw std::invalid_argument(c);
      } catch (const std::logic_error&) {
        throw InvalidInput("--points: \"" + c + "\" in point " + std::to_string(points.size() + 1) + " is not a number");
      }
    }
    if (int(p.size()) != n)
      throw InvalidInput("--points: point " + std::to_string(points.size() + 1) + " has " + std::to_string(p.size()) +
                         " coordinates, expected " + std::to_string(n) + " (points are separated by ';')");
    points.push_back(p);
  }
  if (points.empty()) throw InvalidInput("--points: expected at least one point, e.g. \"0.86,0.3;0.3,0.65\"");
  return points;
}

voronoi::Rules rules_of(const VoronoiArgs& a) {
  if (a.points.empty() == (a.random == 0)) throw InvalidInput("give either --points or --random M");
  const auto points = a.points.empty() ? voronoi::random_points(a.dimension, a.random, a.seed) : parse_points(a.points, a.dimension);
  voronoi::RulesOptions options;
  if (a.children == "scaled") options.children = voronoi::RulesOptions::Children::kScaled;
  else if (a.children == "shifted") options.children = voronoi::RulesOptions::Children::kShifted;
  else throw InvalidInput("--children: expected scaled or shifted, got \"" + a.children + "\"");
  return voronoi::make_rules(a.dimension, a.d, points, options);
}

int voronoi_rules(const VoronoiArgs& a) {
  const voronoi::Rules r = rules_of(a);
  nlohmann::json rules = nlohmann::json::array();
  for (const auto& list : r.rules) {
    nlohmann::json children = nlohmann::json::array();
    for (const voronoi::Rule& c : list) children.push_back({{"offset", c.offset}, {"rule", c.follows + 1}});
    rules.push_back(children);
  }
  nlohmann::json matrix = nlohmann::json::array();
  for (Eigen::Index i = 0; i < r.matrix.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (Eigen::Index j = 0; j < r.matrix.cols(); ++j) row.push_back(r.matrix(i, j));
    matrix.push_back(row);
  }
  nlohmann::json out = {{"dimension", r.dimension}, {"d", r.d}, {"points", r.points}, {"rules", rules},
                        {"matrix", matrix}, {"limit_measures", r.limit_measures},
                        {"graph_condition", r.graph_connected_condition}};
  if (a.json) {
    std::cout << out.dump(1) << "\n";
    return kExitOk;
  }
  for (size_t i = 0; i < r.rules.size(); ++i) {
    std::printf("rule %zu: %zu children following", i + 1, r.rules[i].size());
    for (const voronoi::Rule& c : r.rules[i]) std::printf(" %d", c.follows + 1);
    std::printf("; limit measure %.9f\n", r.limit_measures[i]);
  }
  return kExitOk;
}

int voronoi_cells(const VoronoiArgs& a) {
  const voronoi::Rules r = rules_of(a);
  const VoronoiCells cells = lacuna::voronoi_cells(r, a.level, a.children == "scaled");
  const voronoi::Level& level = cells.level;
  const std::vector<double>& measures = cells.measures;
  nlohmann::json walls = nullptr;
  if (cells.walls)
    walls = {{"boundary_generators", cells.walls->boundary_generators}, {"facets", cells.walls->facets.size()},
             {"measure", cells.walls->measure}};
  if (a.json) {
    std::cout << nlohmann::json{{"dimension", r.dimension}, {"d", r.d}, {"level", a.level}, {"points", level.points.size()},
                                {"measures", measures}, {"limit_measures", r.limit_measures}, {"walls", walls}}
                     .dump(1)
              << "\n";
    return kExitOk;
  }
  std::printf("level %d: %zu points\n", a.level, level.points.size());
  for (size_t i = 0; i < measures.size(); ++i)
    std::printf("colour %zu: measure %.9f (limit %.9f)\n", i + 1, measures[i], r.limit_measures[i]);
  if (!walls.is_null())
    std::printf("walls: %zu facets carried by %zu of the %zu generators, total %s %.9f\n",
                walls["facets"].get<size_t>(), walls["boundary_generators"].get<size_t>(), level.points.size(),
                a.dimension == 2 ? "length" : "area", walls["measure"].get<double>());
  return kExitOk;
}

}  // namespace

std::function<int()> add_voronoi_commands(CLI::App& app) {
  auto args = std::make_shared<VoronoiArgs>();
  CLI::App* voronoi = app.add_subcommand("voronoi", "Fractal Voronoi partitions: substitution rules, cell measures and walls");
  voronoi->require_subcommand(1);
  CLI::App* rules = voronoi->add_subcommand("rules", "The substitution rules, their matrix and the limit cell measures");
  CLI::App* cells = voronoi->add_subcommand("cells", "The measured cell areas (volumes) per colour at a level, and the walls between colours");
  for (CLI::App* sub : {rules, cells}) {
    sub->add_option("--dim", args->dimension, "Dimension, 2 or 3")->check(CLI::IsMember({2, 3}));
    sub->add_option("--d", args->d, "Lacunarity d >= 2")->check(CLI::Range(2, 64));
    sub->add_option("--points", args->points, "Starting points in [0,1)^n: \"x,y;x,y;...\"");
    sub->add_option("--random", args->random, "Or M random starting points")->check(CLI::Range(1, 100000));
    sub->add_option("--seed", args->seed, "Seed for --random");
    sub->add_option("--children", args->children,
                    "scaled: child q = (p + a)/d (default; levels converge to the limit measures), shifted: q = p + a/d");
    sub->add_flag("--json", args->json, "Print JSON");
  }
  cells->add_option("--level", args->level, "Level K")->check(CLI::Range(0, 12));
  return [=]() -> int {
    if (*rules) return voronoi_rules(*args);
    if (*cells) return voronoi_cells(*args);
    return -1;
  };
}

}  // namespace lacuna
