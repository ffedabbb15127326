// The generators called directly: CIFS and NURBS tessellations, space-filling curves and fill rates,
// wallpaper fill patterns, fractal Voronoi rules, cells and walls, lacunar-face rules and measures.
// Keyword arguments follow the command line's options; results are dicts with numpy arrays.
#include "pipeline/generators.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bcifs/topology.h"
#include "cifs/library.h"
#include "cifs/nurbs.h"
#include "curves/sweep.h"
#include "fill/fill.h"
#include "fill/motif_file.h"
#include "fill/wallpaper.h"
#include "pipeline/build_inputs.h"
#include "python/convert.h"
#include "python/objects.h"
#include "export/mesh_io.h"
#include "recipe/cifs_system.h"
#include "recipe/input_parsers.h"
#include "recipe/json_fields.h"
#include "recipe/recipe.h"
#include "solids/parameterize.h"

namespace lacuna {
namespace python {
namespace {

// Re-throws the library's InvalidInput about an argument with the argument's name first.
template <class F>
auto about(const std::string& argument, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const InvalidInput& e) {
    throw InvalidInput(argument + ": " + e.what());
  }
}

cifs::Cifs system_of(const py::handle& system, const std::string& label) {
  if (py::isinstance<py::str>(system) || py::hasattr(system, "__fspath__")) {
    const std::string name = path_of(system);
    return released([&] { return cifs::load_system(name); });
  }
  return cifs::parse_system(to_json(system, "system"), label, "system");
}

std::vector<int> orders_of(const py::handle& orders) {
  if (py::isinstance<py::str>(orders)) {
    const std::string text = orders.cast<std::string>();
    return about("orders", [&] { return curves::parse_orders(text); });
  }
  return orders.cast<std::vector<int>>();
}

curves::CurveKind kind_of(const std::string& kind) {
  if (kind == "hilbert") return curves::CurveKind::kHilbert;
  if (kind == "sierpinski") return curves::CurveKind::kSierpinski;
  throw InvalidInput("kind: expected hilbert, sierpinski or hilbert3d, got \"" + kind + "\"");
}

CurveSurface surface_of(const std::string& surface) {
  if (surface == "plane") return CurveSurface::kPlane;
  if (surface == "sphere") return CurveSurface::kSphere;
  if (surface == "cylinder") return CurveSurface::kCylinder;
  if (surface == "torus") return CurveSurface::kTorus;
  if (surface == "cone") return CurveSurface::kCone;
  if (surface == "cube") return CurveSurface::kCube;
  throw InvalidInput("surface: expected plane, sphere, cylinder, torus, cone or cube, got \"" + surface + "\"");
}

// A curve fill rate as the Python functions give it (curve_fill_rate and each row of curve_fill_rate_series).
py::dict fill_rate_dict(const CurveFillRate& r) {
  py::dict d;
  d["orders"] = r.orders;
  d["segments"] = r.segments;
  d["length"] = r.length;
  d["fill_rate"] = r.fill_rate;
  d["fill_rate_simple"] = r.fill_rate_simple;
  return d;
}

py::array_t<double> matrix_array(const Eigen::MatrixXd& m) {
  py::array_t<double> a({py::ssize_t(m.rows()), py::ssize_t(m.cols())});
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) a.mutable_at(i, j) = m(i, j);
  return a;
}

fill::Motif2 motif_of(const py::handle& motif) {
  if (py::isinstance<py::str>(motif)) {
    const std::string name = motif.cast<std::string>();
    if (name == "circle") return fill::circle_motif();
    if (name == "triangle") return fill::regular_polygon_motif(3);
    if (name == "square") return fill::regular_polygon_motif(4);
    if (name == "hexagon") return fill::regular_polygon_motif(6);
    if (!fill::names_motif_file(name))
      throw InvalidInput(
          "motif: expected circle, triangle, square, hexagon, a number of sides, an N x 2 polygon or a motif file "
          "(.json, .svg), got \"" + name + "\"");
  }
  if (py::isinstance<py::str>(motif) || py::hasattr(motif, "__fspath__")) {
    const std::string file = path_of(motif);
    return about("motif", [&] { return fill::motif_from_file(file); });
  }
  if (py::isinstance<py::int_>(motif)) {
    const int n = motif.cast<int>();
    return about("motif", [&] { return fill::regular_polygon_motif(n); });
  }
  std::vector<Vec2d> points;
  py::array_t<double, py::array::c_style | py::array::forcecast> a = py::array_t<double>::ensure(motif);
  if (!a || a.ndim() != 2 || a.shape(1) != 2) throw py::value_error("motif: expected an N x 2 polygon (mm)");
  for (py::ssize_t i = 0; i < a.shape(0); ++i) points.push_back(Vec2d{a.at(i, 0), a.at(i, 1)});
  return about("motif", [&] { return fill::polygon_motif(points); });
}

fill::BoundaryPolicy policy_of(const std::string& name) {
  if (name == "allow") return fill::BoundaryPolicy::kAllow;
  if (name == "reject") return fill::BoundaryPolicy::kReject;
  if (name == "snap") return fill::BoundaryPolicy::kSnap;
  throw InvalidInput("policy: expected allow, reject or snap, got \"" + name + "\"");
}

// Placed motifs as arrays (one entry per motif), with their outlines when asked for.
py::dict placements_dict(const fill::Motif2& motif, const std::vector<fill::Placement2>& placed, bool outlines) {
  const py::ssize_t n = py::ssize_t(placed.size());
  py::array_t<double> center({n, py::ssize_t(2)}), area(n), scale(n), angle(n);
  py::array_t<bool> mirrored(n);
  py::array_t<int32_t> stabilizer(n);
  py::list outline_list;
  for (py::ssize_t i = 0; i < n; ++i) {
    const fill::Placement2& p = placed[size_t(i)];
    center.mutable_at(i, 0) = p.center_mm.x;
    center.mutable_at(i, 1) = p.center_mm.y;
    area.mutable_at(i) = p.area_mm2;
    scale.mutable_at(i) = p.scale;
    angle.mutable_at(i) = p.angle_rad;
    mirrored.mutable_at(i) = p.mirrored;
    stabilizer.mutable_at(i) = p.stabilizer_order;
    if (outlines) outline_list.append(points_array(fill::placed_outline(motif, p)));
  }
  py::dict d;
  d["center"] = center;
  d["area"] = area;
  d["scale"] = scale;
  d["angle"] = angle;
  d["mirrored"] = mirrored;
  d["stabilizer_order"] = stabilizer;
  if (outlines) d["outlines"] = outline_list;
  return d;
}

voronoi::Rules rules_of(int dimension, int d, const py::object& points, int random, uint64_t seed,
                        const std::string& children) {
  if (points.is_none() == (random == 0)) throw InvalidInput("give either points or random (a number of points)");
  std::vector<std::vector<double>> p;
  if (points.is_none()) {
    p = voronoi::random_points(dimension, random, seed);
  } else {
    p = points.cast<std::vector<std::vector<double>>>();
    for (size_t i = 0; i < p.size(); ++i)
      if (int(p[i].size()) != dimension)
        throw InvalidInput("points: point " + std::to_string(i + 1) + " has " + std::to_string(p[i].size()) +
                           " coordinates, expected " + std::to_string(dimension));
  }
  voronoi::RulesOptions options;
  if (children == "scaled")
    options.children = voronoi::RulesOptions::Children::kScaled;
  else if (children == "shifted")
    options.children = voronoi::RulesOptions::Children::kShifted;
  else
    throw InvalidInput("children: expected scaled or shifted, got \"" + children + "\"");
  return voronoi::make_rules(dimension, d, p, options);
}

py::array_t<double> rows_array(const std::vector<std::vector<double>>& rows, size_t width) {
  py::array_t<double> a({py::ssize_t(rows.size()), py::ssize_t(width)});
  for (size_t i = 0; i < rows.size(); ++i)
    for (size_t k = 0; k < width; ++k)
      a.mutable_at(py::ssize_t(i), py::ssize_t(k)) = k < rows[i].size() ? rows[i][k] : 0;
  return a;
}

py::dict walls_dict(const voronoi::Walls& w) {
  py::dict d;
  d["boundary_generators"] = w.boundary_generators;
  d["facets"] = w.facets.size();
  d["measure"] = w.measure;
  return d;
}

// One recipe input of `type` from keyword arguments, checked as a recipe would check it (messages name `where`).
template <typename Input>
Input one_input(const py::kwargs& keys, const char* type, const char* name, const char* where) {
  nlohmann::json object = to_json(keys, where);
  object["type"] = type;
  const Recipe recipe = parse_recipe(
      nlohmann::json{{"inputs", {{name, object}}}, {"outputs", {{{"of", name}, {"file", std::string(name) + ".stl"}}}}}
          .dump(),
      where);
  return std::get<Input>(recipe.inputs.front().spec);
}

// A face or cell type's counts: N^C_i under `count_key`, N^L_i, R_i, R and the spectral radius.
py::dict lacunarity_dict(const bcifs::Lacunarity& l, int type, const char* count_key) {
  py::dict e;
  e["type"] = type;
  e[count_key] = numbers_array(l.subfaces);
  e["lacunas"] = numbers_array(l.lacunas);
  e["ratio"] = numbers_array(l.ratio);
  e["r_limit"] = l.limit;
  e["spectral_radius"] = l.spectral_radius;
  return e;
}

}  // namespace

void add_generators(py::module_& m) {
  m.def("cifs_library", &cifs::library_names, "The names of the shipped CIFS systems.");
  m.def(
      "cifs_info",
      [](const py::handle& system) {
        cifs::Cifs c = system_of(system, "lacuna.cifs_info");
        cifs::complete_primitives(c.automaton);
        return from_json(cifs::system_json(c));
      },
      py::arg("system"),
      "A system's states (control points, primitive, stationary or not, fixed points), transitions with their "
      "matrices, and control points, as `lacuna cifs info --json` prints them. system: a shipped name, a JSON file "
      "or a system dict (README.md, CIFS systems).");
  m.def(
      "cifs_tessellate",
      [](const py::handle& system, int level) {
        const cifs::Cifs c = system_of(system, "lacuna.cifs_tessellate");
        if (level < 0 || level > 24) throw InvalidInput("level: expected 0 .. 24, got " + std::to_string(level));
        const CifsTessellation t = released([&] { return tessellate_system(c, level); });
        py::dict d;
        d["system"] = c.name;
        d["level"] = level;
        d["pieces"] = t.pieces;
        d["dimension"] = t.dimension;
        d["points"] = points_array(t.points_mm);
        d[t.dimension == 1 ? "polylines" : t.dimension == 2 ? "triangles" : "cells"] = index_rows(t.cells);
        if (t.dimension == 3) d["faces"] = index_rows(t.faces);
        return d;
      },
      py::arg("system"), py::arg("level") = 3,
      "The pieces of a system at a level (at most 20 000 000): points (N x 3, mm) and polylines (index arrays), "
      "triangles (M x 3) or cells (index rows, with their faces).");
  m.def(
      "nurbs_automaton",
      [](int degree, const std::vector<double>& knots) {
        const cifs::NurbsAutomaton na = cifs::nurbs_automaton(degree, knots);
        const std::vector<int> stationary = cifs::stationary_states(na.automaton);
        py::list states;
        for (size_t q = 0; q < na.windows.size(); ++q) {
          py::dict transitions;
          for (const cifs::Transition& t : na.automaton.transitions[q]) {
            py::dict tr;
            tr["to"] = t.target;
            tr["matrix"] = matrix_array(t.matrix);
            transitions[t.symbol == 0 ? "L" : "R"] = tr;
          }
          py::dict s;
          s["index"] = q;
          s["window"] = numbers_array(na.windows[q]);
          s["stationary"] = std::find(stationary.begin(), stationary.end(), int(q)) != stationary.end();
          s["transitions"] = transitions;
          states.append(s);
        }
        py::dict d;
        d["degree"] = degree;
        d["states"] = states;
        return d;
      },
      py::arg("degree"), py::arg("knots"),
      "The automaton of one B-spline piece of `degree` from its 2 degree knots: states with their inter-node "
      "window, stationary flag and transitions L and R (to, matrix: column j is new control point j).");
  m.def(
      "nurbs_tessellate",
      [](int degree, const std::vector<double>& knots, const py::handle& control_points, int level) {
        const nlohmann::json points = to_json(control_points, "control_points");
        const NurbsCurvePoints r =
            released([&] { return nurbs_curve_points(degree, knots, points, level, "lacuna.nurbs_tessellate"); });
        py::dict d;
        d["points"] = points_array(r.points_mm);
        d["parameters"] = numbers_array(r.parameters);
        if (!r.tangents.empty()) d["tangents"] = points_array(r.tangents);
        return d;
      },
      py::arg("degree"), py::arg("knots"), py::arg("control_points"), py::arg("level") = 4,
      "One NURBS piece evaluated by its automaton: points (2^level + 1 of them, mm), their parameters and (levels "
      "up to 16) their unit tangents along the parameter, from the automaton's limit frames. "
      "control_points: degree + 1 rows [x, y, z], or [x, y, z, w] for a rational curve.");
  m.def(
      "curve_points",
      [](const std::string& kind, const py::handle& orders, const std::string& surface, double tolerance) {
        const std::vector<int> o = orders_of(orders);
        const bool hilbert3d = kind == "hilbert3d";
        const curves::CurveKind k = hilbert3d ? curves::CurveKind::kHilbert : kind_of(kind);
        const CurveSurface s = surface_of(surface);
        if (!(tolerance > 0)) throw InvalidInput("tolerance: expected a positive chord tolerance");
        const std::vector<DrawnCurve> drawn =
            about("surface", [&] { return released([&] { return curve_points(k, hilbert3d, o, s, tolerance); }); });
        py::list list;
        for (const DrawnCurve& c : drawn) {
          py::dict e;
          e["order"] = c.order;
          e["closed"] = c.closed;
          e["points"] = points_array(c.points);
          list.append(e);
        }
        py::dict d;
        d["kind"] = kind;
        d["surface"] = surface;
        d["orders"] = list;
        return d;
      },
      py::arg("kind") = "hilbert", py::arg("orders") = "1..3", py::arg("surface") = "plane",
      py::arg("tolerance") = 0.01,
      "The superimposed space-filling curves of `orders` (\"1..6\", \"3,4,6\" or a list) in the square (-1, 1)^2 "
      "(z = 0), mapped onto a unit surface (sphere, cylinder, torus, cone, cube) with chords within `tolerance`, or "
      "(kind hilbert3d) in the cube (-1, 1)^3: orders, a list of {order, closed, points (N x 3)} in drawing order.");
  m.def(
      "curve_fill_rate",
      [](const std::string& kind, const py::handle& orders, double width) {
        const std::vector<int> o = orders_of(orders);
        const curves::CurveKind k = kind_of(kind);
        const CurveFillRate r = about("width", [&] { return released([&] { return curve_fill_rate(k, o, width); }); });
        py::dict d = fill_rate_dict(r);
        d["kind"] = kind;
        d["width"] = width;
        return d;
      },
      py::arg("kind") = "hilbert", py::arg("orders") = "1..3", py::arg("width") = 0.02,
      "The fraction of the square (-1, 1)^2 covered by strokes of `width` (units of the square, side 2) along the "
      "curves: exactly (fill_rate, the union of the strokes) and simply (fill_rate_simple, length x width / 4).");
  m.def(
      "curve_fill_rate_series",
      [](const std::string& kind, const py::handle& orders, double width) {
        const std::vector<int> o = orders_of(orders);
        const curves::CurveKind k = kind_of(kind);
        if (!(width > 0)) throw InvalidInput("width: expected a positive stroke width (the square has side 2)");
        const FillRateSeries s = about("orders", [&] { return released([&] { return curve_fill_rate_series(k, o, width); }); });
        py::list rows;
        for (const CurveFillRate& r : s.rates) {
          rows.append(fill_rate_dict(r));
        }
        py::dict d;
        d["kind"] = kind;
        d["width"] = width;
        d["series"] = rows;
        d["fit_exact"] = py::make_tuple(s.exact_fit.a, s.exact_fit.b);
        d["fit_simple"] = py::make_tuple(s.simple_fit.a, s.simple_fit.b);
        return d;
      },
      py::arg("kind") = "hilbert", py::arg("orders") = "1..5", py::arg("width") = 0.02,
      "The superpositions of the first k orders for every k (series: each as curve_fill_rate) and exponential fits "
      "of their rates in percent against the highest order, 100 rate = a e^(b n) (fit_exact, fit_simple: (a, b)).");
  m.def(
      "curve_surface_fill_rate",
      [](const std::string& kind, const py::handle& orders, double width, const std::string& surface,
         const py::object& patch, const py::object& mesh, int samples, double tolerance) {
        const std::vector<int> o = orders_of(orders);
        const curves::CurveKind k = kind_of(kind);
        if (!(tolerance > 0)) throw InvalidInput("tolerance: expected a positive chord tolerance");
        if (!patch.is_none() && surface != "bspline") throw InvalidInput("patch: only read with surface=\"bspline\"");
        if (!mesh.is_none() && surface != "mesh") throw InvalidInput("mesh: only read with surface=\"mesh\"");
        SurfaceFillRate r;
        if (surface == "bspline" || surface == "mesh") {
          curves::SurfaceMap map;
          if (surface == "bspline") {
            if (patch.is_none()) throw InvalidInput("patch: expected {degree_u, degree_v, count_u, count_v, control_points_mm}");
            map = curves::bspline_map(parse_bspline_patch(JsonObject(to_json(patch, "patch"), "patch", "patch")));
          } else if (py::isinstance<Mesh>(mesh)) {
            map = mesh_patch_map(*mesh.cast<const Mesh&>().data, mesh.cast<const Mesh&>().label);
          } else {
            if (mesh.is_none()) throw InvalidInput("mesh: expected a disk-like surface patch (a lacuna.Mesh or a file)");
            const std::string file = path_of(mesh);
            map = released([&] { return mesh_patch_map(read_mesh(file), file); });
          }
          r = about("surface", [&] {
            return released([&] { return curve_surface_fill_rate(k, o, width, map, samples, tolerance); });
          });
        } else {
          const CurveSurface s = surface_of(surface);
          r = about("surface", [&] {
            return released([&] { return curve_surface_fill_rate(k, o, width, s, samples, tolerance); });
          });
        }
        py::dict d;
        d["kind"] = kind;
        d["surface"] = surface;
        d["orders"] = r.orders;
        d["width"] = width;
        d["samples"] = r.samples;
        d["area"] = r.area;
        d["covered_area"] = r.covered_area;
        d["length"] = r.length;
        d["fill_rate"] = r.fill_rate;
        d["fill_rate_simple"] = r.fill_rate_simple;
        return d;
      },
      py::arg("kind") = "hilbert", py::arg("orders") = "1..3", py::arg("width") = 0.02, py::arg("surface") = "plane",
      py::arg("patch") = py::none(), py::arg("mesh") = py::none(), py::arg("samples") = 0, py::arg("tolerance") = 0.01,
      "The fraction of a surface's area that tubes of diameter `width` along the curves drawn on it cover (as "
      "`lacuna curve fill-rate --surface`): plane, sphere, cylinder, torus, cone, cube, bspline (`patch`: a dict "
      "{degree_u, degree_v, count_u, count_v, control_points_mm}) or mesh (`mesh`: a disk-like lacuna.Mesh or "
      "file). samples: integration cells per side (0: eight across a tube). area, covered_area, length, "
      "fill_rate, fill_rate_simple.");
  m.def(
      "fill_pattern",
      [](const std::string& group, const py::handle& lattice, double c, double N, const py::handle& motif, size_t count,
         size_t max_trials, double gap_mm, uint64_t seed, const std::string& policy, bool random_rotation, int cells,
         const py::object& colors, const py::object& palette) {
        const fill::Group g = about("group", [&] { return fill::group_from_name(group); });
        py::array_t<double, py::array::c_style | py::array::forcecast> l = py::array_t<double>::ensure(lattice);
        if (!l || l.ndim() != 2 || l.shape(0) != 2 || l.shape(1) != 2)
          throw py::value_error("lattice: expected [[ax, ay], [bx, by]] in mm");
        fill::Lattice vectors;
        vectors.a = Vec2d{l.at(0, 0), l.at(0, 1)};
        vectors.b = Vec2d{l.at(1, 0), l.at(1, 1)};
        fill::FillOptions options;
        options.c = c;
        options.N = N;
        options.max_count = count;
        options.max_trials = max_trials;
        options.gap_mm = gap_mm;
        options.seed = seed;
        options.random_rotation = random_rotation;
        const fill::Motif2 shape = motif_of(motif);
        const fill::BoundaryPolicy p = policy_of(policy);
        if (cells < 0 || cells > 50) throw InvalidInput("cells: expected 0 .. 50");
        const fill::WallpaperFill pattern =
            released([&] { return fill::fill_wallpaper(g, vectors, shape, options, p); });
        py::dict d;
        d["group"] = fill::group_name(g);
        d["lattice"] = points_array(std::vector<Vec2d>{pattern.lattice.a, pattern.lattice.b});
        d["c"] = c;
        d["N"] = N;
        d["seed"] = seed;
        d["fill_fraction"] = pattern.fundamental.fill_fraction;
        d["stop_reason"] = pattern.fundamental.stop_reason;
        d["motifs"] = placements_dict(pattern.motif, pattern.fundamental.motifs, false);
        d["fundamental_region"] = points_array(fill::fundamental_region_mm(g, pattern.lattice));
        std::vector<uint32_t> orbits;
        if (cells > 0) d["pattern"] = placements_dict(pattern.motif, fill::replicate(pattern, cells, cells, &orbits), true);
        if (!palette.is_none() && colors.is_none()) throw InvalidInput("palette: only used with colors");
        if (!colors.is_none()) {
          const fill::Coloring by = about("colors", [&] { return fill::coloring_from_name(colors.cast<std::string>()); });
          std::string listed;  // the palette as "#rrggbb,..."
          if (py::isinstance<py::str>(palette)) {
            listed = palette.cast<std::string>();
          } else if (!palette.is_none()) {
            for (const py::handle& entry : palette) listed += (listed.empty() ? "" : ",") + entry.cast<std::string>();
          }
          const std::vector<std::string> colours =
              palette.is_none() ? fill::default_palette() : about("palette", [&] { return fill::parse_palette(listed); });
          const std::vector<std::string> of_motif = fill::motif_palette_colors(pattern.fundamental, by, colours, seed);
          py::list motif_colours, pattern_colours;
          for (const std::string& colour : of_motif) motif_colours.append(colour);
          for (uint32_t o : orbits) pattern_colours.append(of_motif[o]);
          d["colors"] = motif_colours;
          if (cells > 0) d["pattern_colors"] = pattern_colours;
        }
        return d;
      },
      py::arg("group") = "p1", py::arg("lattice") = std::vector<std::vector<double>>{{10, 0}, {0, 10}},
      py::arg("c") = 1.3, py::arg("N") = 2.0, py::arg("motif") = "circle", py::arg("count") = 1000,
      py::arg("max_trials") = 100000, py::arg("gap_mm") = 0.0, py::arg("seed") = 1, py::arg("policy") = "reject",
      py::arg("random_rotation") = false, py::arg("cells") = 0, py::arg("colors") = py::none(),
      py::arg("palette") = py::none(),
      "Fills a wallpaper group's fundamental region by the area rule A / (zeta(c, N) (N + i)^c), as `lacuna fill "
      "pattern`: group (p1 ... p6m), lattice [[ax, ay], [bx, by]] (mm), motif (circle, triangle, square, hexagon, a "
      "number of sides, or an N x 2 polygon), gap_mm (mm) between motifs and their images, policy for motifs meeting "
      "a mirror or rotation centre (allow, reject, snap). Returns fill_fraction, stop_reason, the motifs of the "
      "fundamental region as arrays (center N x 2 mm, area mm^2, scale, angle rad, mirrored, stabilizer_order), the "
      "fundamental_region polygon, and with cells > 0 the pattern replicated over cells x cells unit cells with "
      "every motif's outline (mm). motif may also be a file (.json points, .svg path). colors (size, orbit or "
      "random, from palette: \"#rrggbb,...\" or a list) adds colors (one per motif) and pattern_colors (one per "
      "replicated motif).");
  m.def(
      "voronoi_rules",
      [](int dimension, int d, const py::object& points, int random, uint64_t seed, const std::string& children) {
        const voronoi::Rules r = rules_of(dimension, d, points, random, seed, children);
        py::list rules;
        for (const auto& list : r.rules) {
          py::list kids;
          for (const voronoi::Rule& c : list) {
            py::dict k;
            k["offset"] = numbers_array(c.offset);
            k["rule"] = c.follows + 1;
            kids.append(k);
          }
          rules.append(kids);
        }
        py::dict out;
        out["dimension"] = r.dimension;
        out["d"] = r.d;
        out["points"] = rows_array(r.points, size_t(r.dimension));
        out["rules"] = rules;
        out["matrix"] = matrix_array(r.matrix);
        out["limit_measures"] = numbers_array(r.limit_measures);
        out["graph_condition"] = r.graph_connected_condition;
        return out;
      },
      py::arg("dimension") = 2, py::arg("d") = 2, py::arg("points") = py::none(), py::arg("random") = 0,
      py::arg("seed") = 1, py::arg("children") = "scaled",
      "The substitution rules of a fractal Voronoi partition from its starting points (m x dimension in [0, 1), or "
      "`random` of them from `seed`): rules (per starting point, its children's offset and 1-based rule), matrix "
      "(columns sum to d^dimension), limit_measures (summing to 1), graph_condition.");
  m.def(
      "voronoi_cells",
      [](int dimension, int d, const py::object& points, int random, uint64_t seed, const std::string& children,
         int level) {
        const voronoi::Rules r = rules_of(dimension, d, points, random, seed, children);
        const VoronoiCells cells = released([&] { return voronoi_cells(r, level, children == "scaled"); });
        py::dict out;
        out["dimension"] = r.dimension;
        out["d"] = r.d;
        out["level"] = level;
        out["points"] = cells.level.points.size();
        out["measures"] = numbers_array(cells.measures);
        out["limit_measures"] = numbers_array(r.limit_measures);
        out["walls"] = cells.walls ? py::object(walls_dict(*cells.walls)) : py::object(py::none());
        return out;
      },
      py::arg("dimension") = 2, py::arg("d") = 2, py::arg("points") = py::none(), py::arg("random") = 0,
      py::arg("seed") = 1, py::arg("children") = "scaled", py::arg("level") = 2,
      "Level `level` generated and measured exactly: each colour's area (volume) in torus units (measures), and with "
      "scaled children the walls between colours (boundary_generators, facets, measure).");
  m.def(
      "voronoi_walls",
      [](int dimension, int d, const py::object& points, int random, uint64_t seed, int level) {
        const voronoi::Rules r = rules_of(dimension, d, points, random, seed, "scaled");
        const VoronoiCells cells = released([&] { return voronoi_cells(r, level, true); });
        const voronoi::Walls& w = *cells.walls;
        py::list facets;
        for (const auto& facet : w.facets) {
          py::array_t<double> a({py::ssize_t(facet.size()), py::ssize_t(3)});
          for (size_t i = 0; i < facet.size(); ++i)
            for (int k = 0; k < 3; ++k) a.mutable_at(py::ssize_t(i), k) = facet[i][size_t(k)];
          facets.append(a);
        }
        py::array_t<int32_t> colours({py::ssize_t(w.colours.size()), py::ssize_t(2)});
        for (size_t i = 0; i < w.colours.size(); ++i) {
          colours.mutable_at(py::ssize_t(i), 0) = w.colours[i].first + 1;
          colours.mutable_at(py::ssize_t(i), 1) = w.colours[i].second + 1;
        }
        py::dict out = walls_dict(w);
        out["points"] = w.points;
        out["facets"] = facets;
        out["colours"] = colours;
        return out;
      },
      py::arg("dimension") = 2, py::arg("d") = 2, py::arg("points") = py::none(), py::arg("random") = 0,
      py::arg("seed") = 1, py::arg("level") = 2,
      "The walls between colours of a level (scaled children), in torus units: facets (3D: convex polygons k x 3; "
      "2D: segments, z = 0), colours (per facet, the 1-based colours behind and in front), measure (total length "
      "or area), boundary_generators.");
  m.def(
      "bcifs_rules",
      [](const std::string& boundary, const std::string& params, const std::string& algorithm, int delay) {
        bcifs::FaceType face;
        face.boundary = about("boundary", [&] { return bcifs::parse_boundary(boundary); });
        face.edges = about("params", [&] { return bcifs::parse_edge_set(params); });
        face.algorithm = about("algorithm", [&] { return bcifs::parse_algorithm(algorithm); });
        if (delay < 1 || delay > 16) throw InvalidInput("delay: expected 1 .. 16");
        face.delay = delay;
        const bcifs::RuleSet rules = released([&] { return bcifs::build_rules(face); });
        return from_json(bcifs::rules_json(rules, rules.roots[0]));
      },
      py::arg("boundary"), py::arg("params") = "C2 B2 B2", py::arg("algorithm") = "A1", py::arg("delay") = 1,
      "The rule set of a lacunar face, as `lacuna bcifs rules --json`: every face type reachable, their sub-faces, "
      "incidence and adjacency, and for the face lacunas_1 (N^L_1), subfaces_1 (N^C_1) and r_limit (R).");
  m.def(
      "bcifs_measure",
      [](const py::object& levels, const py::kwargs& keys) {
        const std::pair<int, int> range = levels.cast<std::pair<int, int>>();
        const BcifsPlateInput input = one_input<BcifsPlateInput>(keys, "bcifs_plate", "plate", "lacuna.bcifs_measure");
        const PlateMeasures measures = released([&] {
          const bcifs::Plate plate = build_plate(input, "lacuna.bcifs_measure", "inputs.plate");
          return measure_plate(plate, range.first, range.second);
        });
        py::list faces;
        for (size_t f = 0; f < measures.faces.size(); ++f)
          faces.append(lacunarity_dict(measures.faces[f], measures.face_types[f], "subfaces"));
        py::dict boxes;
        boxes["region_dimension"] = measures.region.dimension;
        boxes["boundary_dimension"] = measures.boundary.dimension;
        boxes["log_inverse_size"] = numbers_array(measures.boundary.log_inverse_size);
        boxes["boundary_log_count"] = numbers_array(measures.boundary.log_count);
        boxes["region_log_count"] = numbers_array(measures.region.log_count);
        py::list polygons;
        for (const auto& p : measures.polygons) polygons.append(points_array(p));
        py::dict d;
        d["topology"] = faces;
        d["levels"] = py::make_tuple(range.first, range.second);
        d["area_mm2"] = numbers_array(measures.geometry.area);
        d["perimeter_mm"] = numbers_array(measures.geometry.perimeter);
        d["F_A"] = measures.geometry.area_factor;
        d["F_P"] = measures.geometry.perimeter_factor;
        d["box_counting"] = boxes;
        d["polygons"] = polygons;
        return d;
      },
      py::arg("levels") = std::pair<int, int>{0, 4},
      "The measures `lacuna bcifs measure` prints for a plate given by the keys of a bcifs_plate input (face or "
      "faces + shared, radius_mm, gap_fraction, ...), between levels (first, last): per face its N^C_i (subfaces), "
      "N^L_i (lacunas), R_i (ratio) and limit R; areas A_i (mm^2) and perimeters P_i (mm), F_A, F_P, box-counting "
      "dimensions, and the sub-face polygons of the last level (mm).");
  m.def(
      "bcifs_volume_measure",
      [](int last, const py::kwargs& keys) {
        if (last < 0 || last > kMaxTopologyLevel)
          throw InvalidInput("last: expected a level from 0 to " + std::to_string(kMaxTopologyLevel) + ", got " +
                             std::to_string(last));
        const BcifsVolumeInput input =
            one_input<BcifsVolumeInput>(keys, "bcifs_volume", "volume", "lacuna.bcifs_volume_measure");
        const VolumeCellMeasures vm = released([&] { return measure_volume(input.spec, input.options, last); });
        py::list cells;
        for (size_t c = 0; c < vm.cells.size(); ++c) cells.append(lacunarity_dict(vm.cells[c], vm.cell_types[c], "cells"));
        py::dict boxes;
        boxes["grid"] = kVolumeBoxGrid;
        boxes["fill"] = vm.grid_fill;
        boxes["region_dimension"] = vm.region.dimension;
        boxes["boundary_dimension"] = vm.boundary.dimension;
        boxes["log_inverse_size"] = numbers_array(vm.region.log_inverse_size);
        boxes["region_log_count"] = numbers_array(vm.region.log_count);
        boxes["boundary_log_count"] = numbers_array(vm.boundary.log_count);
        py::list sections;
        for (size_t axis = 0; axis < 3; ++axis) {
          py::array_t<uint8_t> mask({py::ssize_t(kSectionPixels), py::ssize_t(kSectionPixels)});
          std::copy(vm.sections[axis].begin(), vm.sections[axis].end(), mask.mutable_data());
          py::dict e;
          e["axis"] = std::string(1, "xyz"[axis]);
          e["at_mm"] = vm.section_mm[axis];
          e["mask"] = mask;
          sections.append(e);
        }
        const bcifs::VolumeMeasures& g = vm.geometry;
        py::dict d;
        d["topology"] = cells;
        d["geometry_levels"] = py::make_tuple(0, vm.geometry_last);
        d["volume_mm3"] = numbers_array(g.volume);
        d["surface_mm2"] = numbers_array(g.surface);
        d["F_V"] = g.volume_factor;
        d["F_S"] = g.surface_factor;
        d["tunnels"] = numbers_array(g.tunnels);
        d["genus"] = numbers_array(g.genus);
        d["box_counting"] = boxes;
        d["sections"] = sections;
        return d;
      },
      py::arg("last") = 3,
      "The measures `lacuna bcifs measure` prints for a lacunar volume given by the keys of a bcifs_volume input "
      "(cell, edge_mm or cells, walls, edge, params, interior, lacuna_scale, ...), levels 0 to `last`: per cell of "
      "the assembly N^C_i (cells), N^L_i (lacunas), R_i (ratio) and R; volumes V_i, surfaces S_i, F_V, F_S, tunnels "
      "and genus to the deepest level of at most 300 000 cells (geometry_levels); at that level the 3D box counting "
      "on a 256^3 grid (fill: the share of voxel centres inside) and the sections through the middle of its box "
      "(x, y, z: 1024 x 1024 masks, rows along the second of the other two axes).");
}

}  // namespace python
}  // namespace lacuna
