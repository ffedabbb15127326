#include "cli/fill_commands.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/exit_codes.h"
#include "cli/number_checks.h"
#include "errors.h"
#include "fill/fill.h"
#include "fill/motif_file.h"
#include "fill/wallpaper.h"

namespace lacuna {
namespace {

struct FillArgs {
  std::string group = "p1";
  std::string lattice = "10,0;0,10";
  double c = 1.3;
  double N = 2;
  std::string motif = "circle";
  size_t count = 1000;
  size_t max_trials = 100000;
  double gap = 0;
  uint64_t seed = 1;
  std::string policy = "reject";
  bool random_rotation = false;
  std::string svg;
  std::string colors;   // size, orbit or random; empty: black
  std::string palette;  // "#rrggbb,..."; empty: the default
  int cells = 3;
  bool json = false;
};

fill::Lattice parse_lattice(const std::string& text) {
  double v[4];
  char sep1 = 0, sep2 = 0, sep3 = 0;
  std::istringstream in(text);
  if (!(in >> v[0] >> sep1 >> v[1] >> sep2 >> v[2] >> sep3 >> v[3]) || sep1 != ',' || sep2 != ';' || sep3 != ',' ||
      !(in >> std::ws).eof())
    throw InvalidInput("--lattice: expected \"ax,ay;bx,by\" in mm (e.g. \"10,0;0,10\"), got \"" + text + "\"");
  fill::Lattice l;
  l.a = Vec2d{v[0], v[1]};
  l.b = Vec2d{v[2], v[3]};
  return l;
}

fill::Motif2 motif_of(const std::string& name) {
  if (name == "circle") return fill::circle_motif();
  if (name == "triangle") return fill::regular_polygon_motif(3);
  if (name == "square") return fill::regular_polygon_motif(4);
  if (name == "hexagon") return fill::regular_polygon_motif(6);
  if (name.rfind("ngon:", 0) == 0) {
    try {
      size_t used = 0;
      const int n = std::stoi(name.substr(5), &used);
      if (used == name.size() - 5) return fill::regular_polygon_motif(n);
    } catch (const std::logic_error&) {
    }
  }
  if (fill::names_motif_file(name)) {
    try {
      return fill::motif_from_file(name);
    } catch (const InvalidInput& e) {
      throw InvalidInput(std::string("--motif: ") + e.what());
    }
  }
  throw InvalidInput("--motif: expected circle, triangle, square, hexagon, ngon:N or a motif file (.json points, .svg path), got \"" +
                     name + "\"");
}

fill::BoundaryPolicy policy_of(const std::string& name) {
  if (name == "allow") return fill::BoundaryPolicy::kAllow;
  if (name == "reject") return fill::BoundaryPolicy::kReject;
  if (name == "snap") return fill::BoundaryPolicy::kSnap;
  throw InvalidInput("--policy: expected allow, reject or snap, got \"" + name + "\"");
}

int fill_pattern(const FillArgs& args) {
  fill::Group group{};
  try {
    group = fill::group_from_name(args.group);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("--group: ") + e.what());
  }
  fill::FillOptions options;
  options.c = args.c;
  options.N = args.N;
  options.max_count = args.count;
  options.max_trials = args.max_trials;
  options.gap_mm = args.gap;
  options.seed = args.seed;
  options.random_rotation = args.random_rotation;
  if (!args.palette.empty() && args.colors.empty()) throw InvalidInput("--palette: only used with --colors");
  std::vector<std::string> palette = fill::default_palette();
  if (!args.palette.empty()) {
    try {
      palette = fill::parse_palette(args.palette);
    } catch (const InvalidInput& e) {
      throw InvalidInput(std::string("--palette: ") + e.what());
    }
  }
  fill::Coloring coloring = fill::Coloring::kOrbit;
  if (!args.colors.empty()) {
    try {
      coloring = fill::coloring_from_name(args.colors);
    } catch (const InvalidInput& e) {
      throw InvalidInput(std::string("--colors: ") + e.what());
    }
  }
  const fill::WallpaperFill pattern = fill::fill_wallpaper(group, parse_lattice(args.lattice), motif_of(args.motif), options,
                                                          policy_of(args.policy));
  // Each motif's colour (its images take it too), when asked for.
  std::vector<std::string> fills;
  if (!args.colors.empty()) fills = fill::motif_palette_colors(pattern.fundamental, coloring, palette, args.seed);
  if (!args.svg.empty()) {
    // Written whole under a temporary name, then renamed: never a partial picture.
    const std::filesystem::path target(args.svg), temporary = target.string() + ".partial";
    {
      std::ofstream out(temporary, std::ios::binary);
      if (!out) throw IoError(args.svg + ": cannot write the picture");
      out << fill::wallpaper_svg(pattern, args.cells, fills);
      if (!out.flush()) throw IoError(args.svg + ": cannot write the picture");
    }
    std::filesystem::rename(temporary, target);
  }
  const fill::FillResult2& r = pattern.fundamental;
  if (args.json) {
    nlohmann::json motifs = nlohmann::json::array();
    for (size_t i = 0; i < r.motifs.size(); ++i) {
      const fill::Placement2& p = r.motifs[i];
      motifs.push_back({{"center", {p.center_mm.x, p.center_mm.y}},
                        {"area", p.area_mm2},
                        {"scale", p.scale},
                        {"angle", p.angle_rad},
                        {"mirrored", p.mirrored},
                        {"stabilizer_order", p.stabilizer_order}});
      if (!fills.empty()) motifs.back()["color"] = fills[i];
    }
    nlohmann::json lattice = {{"a", {pattern.lattice.a.x, pattern.lattice.a.y}}, {"b", {pattern.lattice.b.x, pattern.lattice.b.y}}};
    std::cout << nlohmann::json{{"group", fill::group_name(group)}, {"lattice", lattice}, {"c", args.c}, {"N", args.N},
                                {"seed", args.seed}, {"fill_fraction", r.fill_fraction}, {"stop_reason", r.stop_reason},
                                {"motifs", motifs}}
                     .dump(1)
              << "\n";
    return kExitOk;
  }
  std::printf("%s, c = %g, N = %g: %zu motifs in the fundamental region, fill fraction %.6f (%s)\n",
              fill::group_name(group).c_str(), args.c, args.N, r.motifs.size(), r.fill_fraction, r.stop_reason.c_str());
  if (!args.svg.empty()) std::printf("picture: %s (%d x %d cells)\n", args.svg.c_str(), args.cells, args.cells);
  return kExitOk;
}

}  // namespace

std::function<int()> add_fill_commands(CLI::App& app) {
  auto args = std::make_shared<FillArgs>();
  CLI::App* fill = app.add_subcommand("fill", "Random fractal fillings");
  fill->require_subcommand(1);
  CLI::App* pattern = fill->add_subcommand("pattern", "Fill a wallpaper group's fundamental region by the area rule");
  pattern->add_option("--group", args->group, "One of the 17 wallpaper groups: p1 p2 pm pg cm pmm pmg pgg cmm p4 p4m p4g p3 p3m1 p31m p6 p6m");
  pattern->add_option("--lattice", args->lattice, "Lattice vectors \"ax,ay;bx,by\" in mm (default 10,0;0,10)");
  pattern->add_option("--c", args->c, "Exponent of the area rule, > 1 (dimension 2/c)")->check(finite_number());
  pattern->add_option("--N", args->N, "Offset of the area rule, > 1")->check(finite_number());
  pattern->add_option("--motif", args->motif,
                      "circle, triangle, square, hexagon, ngon:N, or a file: .json (a list of [x, y] points) or .svg (a\n"
                      "path of straight segments); any simple polygon, its symmetry detected");
  pattern->add_option("--count", args->count, "Most motifs in the fundamental region")
      ->check(CLI::Range(size_t(1), fill::kMaxFillCount));
  pattern->add_option("--max-trials", args->max_trials, "Random positions tried per motif before stopping");
  pattern->add_option("--gap", args->gap, "Least distance between motifs, images included (mm)")
      ->check(non_negative_number());
  pattern->add_option("--seed", args->seed, "Seed of the generator");
  pattern->add_option("--policy", args->policy, "Motifs meeting a mirror or rotation centre: allow, reject or snap");
  pattern->add_flag("--random-rotation", args->random_rotation, "Turn every motif by a random angle");
  pattern->add_option("--svg", args->svg, "Write an SVG picture of the replicated pattern");
  pattern->add_option("--cells", args->cells, "Unit cells along each side in the picture")->check(CLI::Range(1, 50));
  pattern->add_option("--colors", args->colors,
                      "Colour the motifs (each with all its images) by size class (octaves of area), by orbit (one\n"
                      "colour per motif, in turn) or at random (seeded): size, orbit or random");
  pattern->add_option("--palette", args->palette, "With --colors: \"#rrggbb,#rrggbb,...\" (default: 8 colours, ColorBrewer Dark2)");
  pattern->add_flag("--json", args->json, "Print JSON: fill_fraction, stop_reason, motifs of the fundamental region");
  return [=]() -> int {
    if (*pattern) return fill_pattern(*args);
    return -1;
  };
}

}  // namespace lacuna
