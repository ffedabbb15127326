#include "cli/curve_commands.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "curves/curves.h"
#include "curves/sweep.h"
#include "cli/exit_codes.h"
#include "errors.h"

namespace lacuna {
namespace {

struct CurveArgs {
  std::string kind = "hilbert";
  std::string orders = "1..3";
  std::string surface = "plane";
  double tolerance = 0.01;
  double width = 0.02;
  bool json = false;
  bool csv = false;
};

std::vector<int> parse_orders(const std::string& text) {
  try {
    return curves::parse_orders(text);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("--orders: ") + e.what());
  }
}

curves::CurveKind kind_of(const std::string& kind) {
  if (kind == "hilbert") return curves::CurveKind::kHilbert;
  if (kind == "sierpinski") return curves::CurveKind::kSierpinski;
  throw InvalidInput("--kind: expected hilbert, sierpinski or hilbert3d, got \"" + kind + "\"");
}

// One polyline of the output: its order, its points in drawing order, whether it closes.
struct Drawn {
  int order;
  std::vector<Vec3d> points;
  bool closed;
};

int curve_points(const CurveArgs& args) {
  const std::vector<int> orders = parse_orders(args.orders);
  std::vector<Drawn> drawn;
  uint64_t total = 0;
  auto keep = [&](int order, std::vector<Vec3d> points, bool closed) {
    total += points.size();
    if (total > 20'000'000) throw ResourceLimit("more than 20 000 000 points; ask for lower orders");
    drawn.push_back(Drawn{order, std::move(points), closed});
  };
  if (args.kind == "hilbert3d") {
    if (args.surface != "plane" && args.surface != "cube") throw InvalidInput("--surface: a 3D Hilbert curve fills the cube; it takes no surface");
    for (const curves::Curve3& c : curves::superposition3d(orders)) keep(c.order, c.polyline.points, c.polyline.closed);
  } else {
    const curves::CurveKind kind = kind_of(args.kind);
    curves::MapOptions options;
    options.tolerance_mm = args.tolerance;
    if (args.surface == "cube") {
      for (int order : orders)
        for (const curves::Polyline3& line : curves::cube_curve(kind, order, options)) keep(order, line.points, line.closed);
    } else {
      curves::SurfaceMap map;
      if (args.surface == "sphere") map = curves::sphere_map();
      else if (args.surface == "cylinder") map = curves::cylinder_map();
      else if (args.surface == "torus") map = curves::torus_map();
      else if (args.surface == "cone") map = curves::cone_map();
      else if (args.surface != "plane")
        throw InvalidInput("--surface: expected plane, sphere, cylinder, torus, cone or cube, got \"" + args.surface + "\"");
      for (const curves::Curve2& c : curves::superposition(kind, orders)) {
        if (args.surface == "plane") {
          std::vector<Vec3d> points;
          for (const Vec2d& p : c.polyline.points) points.push_back(Vec3d{p.x, p.y, 0});
          keep(c.order, std::move(points), c.polyline.closed);
        } else {
          curves::Polyline3 line = curves::map_polyline(c.polyline, map, options);
          keep(c.order, line.points, line.closed);
        }
      }
    }
  }
  if (args.csv) {
    std::cout << "order,polyline,x,y,z\n";
    char line[160];
    for (size_t i = 0; i < drawn.size(); ++i)
      for (const Vec3d& p : drawn[i].points) {
        std::snprintf(line, sizeof line, "%d,%zu,%.17g,%.17g,%.17g\n", drawn[i].order, i, p.x, p.y, p.z);
        std::cout << line;
      }
    return kExitOk;
  }
  nlohmann::json j = {{"kind", args.kind}, {"surface", args.surface}, {"orders", nlohmann::json::array()}};
  for (const Drawn& d : drawn) {
    nlohmann::json points = nlohmann::json::array();
    for (const Vec3d& p : d.points) points.push_back({p.x, p.y, p.z});
    j["orders"].push_back({{"order", d.order}, {"closed", d.closed}, {"points", std::move(points)}});
  }
  if (args.json) {
    std::cout << j.dump() << "\n";
    return kExitOk;
  }
  for (const Drawn& d : drawn)
    std::printf("order %d: %zu points%s\n", d.order, d.points.size(), d.closed ? ", closed" : "");
  std::printf("(--json or --csv for the points)\n");
  return kExitOk;
}

int curve_fill_rate(const CurveArgs& args) {
  if (!(args.width > 0)) throw InvalidInput("--width: expected a positive stroke width (the square has side 2)");
  const std::vector<curves::Curve2> set = curves::superposition(kind_of(args.kind), parse_orders(args.orders));
  const std::vector<curves::Polyline2> lines = curves::polylines_of(set);
  double length = 0;
  uint64_t segments = 0;
  for (const curves::Polyline2& l : lines) {
    const size_t n = l.points.size();
    for (size_t i = 0; i + 1 < n + (l.closed ? 1 : 0); ++i) {
      const Vec2d d = l.points[(i + 1) % n] - l.points[i];
      length += std::hypot(d.x, d.y);
      ++segments;
    }
  }
  const double exact = curves::fill_rate_exact(lines, args.width), simple = curves::fill_rate_estimate(lines, args.width);
  if (args.json) {
    std::vector<int> orders;
    for (const curves::Curve2& c : set) orders.push_back(c.order);
    std::cout << nlohmann::json{{"kind", args.kind}, {"orders", orders}, {"width", args.width}, {"segments", segments},
                                {"length", length}, {"fill_rate", exact}, {"fill_rate_simple", simple}}
                     .dump(2)
              << "\n";
    return kExitOk;
  }
  std::printf("%s orders %s, width %g: %llu segments, length %.6g\n", args.kind.c_str(), args.orders.c_str(), args.width,
              static_cast<unsigned long long>(segments), length);
  std::printf("fill rate (union of the strokes): %.4f %%\n", 100 * exact);
  std::printf("fill rate (length x width / area): %.4f %%\n", 100 * simple);
  return kExitOk;
}

}  // namespace

std::function<int()> add_curve_commands(CLI::App& app) {
  auto args = std::make_shared<CurveArgs>();
  CLI::App* curve = app.add_subcommand("curve", "Space-filling curves: points and fill rates");
  curve->require_subcommand(1);
  CLI::App* points = curve->add_subcommand("points", "The points of each order, in drawing order (square (-1, 1)^2 or a surface)");
  CLI::App* fill = curve->add_subcommand("fill-rate", "The fraction of the square the curves cover as strokes of a width");
  for (CLI::App* sub : {points, fill}) {
    sub->add_option("--kind", args->kind, "hilbert, sierpinski (or hilbert3d for points)");
    sub->add_option("--orders", args->orders, "FROM..TO (e.g. 1..6) or a list such as 3,4,6");
    sub->add_flag("--json", args->json, "Print JSON");
  }
  points->add_option("--surface", args->surface, "plane, sphere, cylinder, torus, cone or cube");
  points->add_option("--tolerance", args->tolerance, "Chord tolerance on a surface (units of the square)")
      ->check(CLI::PositiveNumber);
  points->add_flag("--csv", args->csv, "Print order,polyline,x,y,z lines");
  fill->add_option("--width", args->width, "Stroke width (the square has side 2)")->check(CLI::PositiveNumber);
  return [=]() -> int {
    if (*points) return curve_points(*args);
    if (*fill) return curve_fill_rate(*args);
    return -1;
  };
}

}  // namespace lacuna
