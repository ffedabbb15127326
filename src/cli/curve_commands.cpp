#include "cli/curve_commands.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "curves/curves.h"
#include "curves/sweep.h"
#include "cli/exit_codes.h"
#include "cli/number_checks.h"
#include "errors.h"
#include "export/mesh_io.h"
#include "pipeline/generators.h"
#include "recipe/input_parsers.h"
#include "recipe/json_fields.h"
#include "solids/parameterize.h"

namespace lacuna {
namespace {

struct CurveArgs {
  std::string kind = "hilbert";
  std::string orders = "1..3";
  std::string surface = "plane";
  std::string patch;  // --surface bspline: the patch file (JSON)
  std::string mesh;   // --surface mesh: the disk-like mesh file
  double tolerance = 0.01;
  double width = 0.02;
  int samples = 0;
  bool surface_given = false;
  bool json = false;
  bool csv = false;
  bool series = false;
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

CurveSurface surface_of(const std::string& surface) {
  if (surface == "plane") return CurveSurface::kPlane;
  if (surface == "sphere") return CurveSurface::kSphere;
  if (surface == "cylinder") return CurveSurface::kCylinder;
  if (surface == "torus") return CurveSurface::kTorus;
  if (surface == "cone") return CurveSurface::kCone;
  if (surface == "cube") return CurveSurface::kCube;
  throw InvalidInput("--surface: expected plane, sphere, cylinder, torus, cone, cube, bspline or mesh, got \"" + surface +
                     "\"");
}

bool is_patch(const CurveArgs& args) { return args.surface == "bspline" || args.surface == "mesh"; }

// --surface bspline with --patch FILE (the object a curve input's "patch" is), or --surface mesh with
// --mesh FILE (a disk-like patch, flattened onto the square as the curve input does).
curves::SurfaceMap patch_map(const CurveArgs& args) {
  if (args.surface == "bspline") {
    if (args.patch.empty()) throw InvalidInput("--surface bspline: expected --patch FILE (degree_u, degree_v, count_u, count_v, control_points_mm)");
    return curves::bspline_map(parse_bspline_patch(JsonObject(read_json_file(args.patch, "a B-spline patch (.json)"), args.patch, "patch")));
  }
  if (args.mesh.empty()) throw InvalidInput("--surface mesh: expected --mesh FILE (a disk-like surface patch)");
  return mesh_patch_map(read_mesh(args.mesh), args.mesh);
}

void check_patch_options(const CurveArgs& args) {
  if (!args.patch.empty() && args.surface != "bspline") throw InvalidInput("--patch: only read with --surface bspline");
  if (!args.mesh.empty() && args.surface != "mesh") throw InvalidInput("--mesh: only read with --surface mesh");
}

int curve_points(const CurveArgs& args) {
  const std::vector<int> orders = parse_orders(args.orders);
  const bool hilbert3d = args.kind == "hilbert3d";
  if (hilbert3d && args.surface != "plane" && args.surface != "cube")
    throw InvalidInput("--surface: a 3D Hilbert curve fills the cube; it takes no surface");
  check_patch_options(args);
  const std::vector<DrawnCurve> drawn =
      is_patch(args) ? lacuna::curve_points(kind_of(args.kind), orders, patch_map(args), args.tolerance)
                     : lacuna::curve_points(hilbert3d ? curves::CurveKind::kHilbert : kind_of(args.kind), hilbert3d,
                                            orders, surface_of(args.surface), args.tolerance);
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
  for (const DrawnCurve& d : drawn) {
    nlohmann::json points = nlohmann::json::array();
    for (const Vec3d& p : d.points) points.push_back({p.x, p.y, p.z});
    j["orders"].push_back({{"order", d.order}, {"closed", d.closed}, {"points", std::move(points)}});
  }
  if (args.json) {
    std::cout << j.dump() << "\n";
    return kExitOk;
  }
  for (const DrawnCurve& d : drawn)
    std::printf("order %d: %zu points%s\n", d.order, d.points.size(), d.closed ? ", closed" : "");
  std::printf("(--json or --csv for the points)\n");
  return kExitOk;
}

// On a surface: the tubes' footprint over the surface's area (curve_surface_fill_rate).
int curve_surface_fill_rate(const CurveArgs& args) {
  if (!(args.width > 0)) throw InvalidInput("--width: expected a positive tube diameter");
  check_patch_options(args);
  const curves::CurveKind kind = kind_of(args.kind);
  const std::vector<int> orders = parse_orders(args.orders);
  const SurfaceFillRate r =
      is_patch(args) ? lacuna::curve_surface_fill_rate(kind, orders, args.width, patch_map(args), args.samples, args.tolerance)
                     : lacuna::curve_surface_fill_rate(kind, orders, args.width, surface_of(args.surface), args.samples,
                                                       args.tolerance);
  if (args.json) {
    std::cout << nlohmann::json{{"kind", args.kind},         {"surface", args.surface},
                                {"orders", r.orders},        {"width", args.width},
                                {"samples", r.samples},      {"tolerance", args.tolerance},
                                {"area", r.area},            {"covered_area", r.covered_area},
                                {"length", r.length},        {"fill_rate", r.fill_rate},
                                {"fill_rate_simple", r.fill_rate_simple}}
                     .dump(2)
              << "\n";
    return kExitOk;
  }
  std::printf("%s orders %s on the %s, tubes of width %g: length %.6g, surface area %.6g\n", args.kind.c_str(),
              args.orders.c_str(), args.surface.c_str(), args.width, r.length, r.area);
  std::printf("fill rate (the tubes' footprint, %d x %d samples%s): %.4f %%\n", r.samples, r.samples,
              args.surface == "cube" ? " per face" : "", 100 * r.fill_rate);
  std::printf("fill rate (length x width / area): %.4f %%\n", 100 * r.fill_rate_simple);
  return kExitOk;
}

// The growing superpositions of the orders and the exponential fits of their rates (the source's form).
int curve_fill_rate_series(const CurveArgs& args) {
  if (args.surface_given) throw InvalidInput("--series: measured in the square only (leave out --surface)");
  if (!(args.width > 0)) throw InvalidInput("--width: expected a positive stroke width (the square has side 2)");
  const std::vector<int> orders = parse_orders(args.orders);
  FillRateSeries s;
  try {
    s = lacuna::curve_fill_rate_series(kind_of(args.kind), orders, args.width);
  } catch (const InvalidInput& e) {
    throw InvalidInput(std::string("--orders: ") + e.what());
  }
  if (args.json) {
    nlohmann::json rows = nlohmann::json::array();
    for (const CurveFillRate& r : s.rates)
      rows.push_back({{"orders", r.orders}, {"segments", r.segments}, {"length", r.length}, {"fill_rate", r.fill_rate},
                      {"fill_rate_simple", r.fill_rate_simple}});
    std::cout << nlohmann::json{{"kind", args.kind},
                                {"width", args.width},
                                {"series", rows},
                                {"fit_percent", {{"exact", {{"a", s.exact_fit.a}, {"b", s.exact_fit.b}}},
                                                 {"simple", {{"a", s.simple_fit.a}, {"b", s.simple_fit.b}}}}}}
                     .dump(2)
              << "\n";
    return kExitOk;
  }
  std::printf("%s, width %g: superpositions of orders %d..n\n", args.kind.c_str(), args.width, s.rates[0].orders[0]);
  std::printf("%4s %12s %12s\n", "n", "union %", "simple %");
  for (const CurveFillRate& r : s.rates)
    std::printf("%4d %12.4f %12.4f\n", r.orders.back(), 100 * r.fill_rate, 100 * r.fill_rate_simple);
  std::printf("fit (least squares of ln): union %.4g e^(%.4g n) %%, simple %.4g e^(%.4g n) %%\n", s.exact_fit.a,
              s.exact_fit.b, s.simple_fit.a, s.simple_fit.b);
  return kExitOk;
}

int curve_fill_rate(const CurveArgs& args) {
  if (args.series) return curve_fill_rate_series(args);
  if (args.surface_given) return curve_surface_fill_rate(args);
  if (!(args.width > 0)) throw InvalidInput("--width: expected a positive stroke width (the square has side 2)");
  const CurveFillRate r = lacuna::curve_fill_rate(kind_of(args.kind), parse_orders(args.orders), args.width);
  const uint64_t segments = r.segments;
  const double length = r.length, exact = r.fill_rate, simple = r.fill_rate_simple;
  if (args.json) {
    std::cout << nlohmann::json{{"kind", args.kind}, {"orders", r.orders}, {"width", args.width}, {"segments", segments},
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
  points->add_option("--surface", args->surface, "plane, sphere, cylinder, torus, cone, cube, bspline (--patch) or mesh (--mesh)");
  points->add_option("--tolerance", args->tolerance, "Chord tolerance on a surface (units of the square)")
      ->check(positive_number());
  points->add_flag("--csv", args->csv, "Print order,polyline,x,y,z lines");
  fill->add_option("--width", args->width, "Stroke width (the square has side 2); on a surface the tubes' diameter")
      ->check(positive_number());
  fill->add_option("--surface", args->surface,
                   "plane, sphere, cylinder, torus, cone, cube, bspline (--patch) or mesh (--mesh): the fraction of\n"
                   "the surface's area the tubes along the curves drawn on it cover (without it: the square's\n"
                   "strokes, exactly)");
  fill->add_flag("--series", args->series,
                 "The superpositions of the first k orders for every k, and exponential fits of their rates in\n"
                 "percent against the highest order (a e^(b n), least squares of the logarithm)");
  fill->add_option("--samples", args->samples, "On a surface: integration cells per side (default: 8 across a tube)")
      ->check(CLI::Range(16, 20000));
  fill->add_option("--tolerance", args->tolerance, "On a surface: chord tolerance of the drawn curves")
      ->check(positive_number());
  for (CLI::App* sub : {points, fill}) {
    sub->add_option("--patch", args->patch,
                    "With --surface bspline: a JSON file {degree_u, degree_v, count_u, count_v, control_points_mm (u fastest)}");
    sub->add_option("--mesh", args->mesh, "With --surface mesh: a disk-like surface patch (.stl, .obj, .ply, .3mf or .drc)");
  }
  return [=]() -> int {
    if (*points) return curve_points(*args);
    if (*fill) {
      args->surface_given = fill->count("--surface") > 0;
      return curve_fill_rate(*args);
    }
    return -1;
  };
}

}  // namespace lacuna
