#include "pipeline/build_inputs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>

#include "bcifs/realize.h"
#include "bcifs/topology.h"
#include "bcifs/volume.h"
#include "cifs/solid_input.h"
#include "curves/curves.h"
#include "curves/sweep.h"
#include "errors.h"
#include "export/mesh_io.h"
#include "fill/fill.h"
#include "fill/motif_solids.h"
#include "fill/polyhedra.h"
#include "fill/wallpaper.h"
#include "infill/bisection.h"
#include "infill/lattice.h"
#include "solids/check.h"
#include "solids/parameterize.h"
#include "solids/repair.h"
#include "solids/volume.h"
#include "solids/voxelize.h"
#include "util/progress.h"
#include "util/system.h"
#include "voronoi/pieces.h"
#include "voronoi/rules.h"
#include "voronoi/walls.h"

namespace lacuna {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

using Field = std::function<double(const Vec3d&)>;

// Builds one input: its options, where it is in the recipe, and what it may use.
class Builder {
 public:
  Builder(const RecipeInput& input, const BuildContext& context)
      : in_(input), context_(context), recipe_(*context.recipe), vopt_{recipe_.voxel_size_mm, recipe_.band_voxels} {}

  BuiltInput build() {
    std::visit([this](const auto& options) { add(options); }, in_.spec);
    return std::move(out_);
  }

 private:
  // "<recipe>: <json path>", what messages about the input start with.
  std::string where() const { return recipe_.file + ": " + in_.json_path; }

  // Throws InvalidInput "<recipe>: <json path>[.key]: message".
  [[noreturn]] void fail(const std::string& key, const std::string& message) const {
    throw InvalidInput(recipe_.file + ": " + (key.empty() ? in_.json_path : in_.json_path + "." + key) + ": " + message);
  }

  // Whether a message already names the recipe (then it is passed on as it is).
  bool names_recipe(const InvalidInput& e) const { return std::string(e.what()).find(recipe_.file) == 0; }

  const GeometrySet& geometry_of(const std::string& name) const { return context_.built->at(name).geometry; }

  Box3 box_of(const std::string& name) const { return bounding_box(geometry_of(name)); }

  // Distance inside another input's solid (mm, 0 outside), exact up to `max_depth_mm`.
  Field depth_in(const std::string& name, double max_depth) const {
    // A field for grading needs no finer voxels than a tenth of its range.
    VolumeOptions wide;
    wide.voxel_size_mm = std::max(vopt_.voxel_size_mm, max_depth / 10);
    wide.half_band_voxels = max_depth / wide.voxel_size_mm + 2;
    auto volume = std::make_shared<Volume>(voxelize(geometry_of(name), wide));
    return [volume, max_depth](const Vec3d& p) { return std::clamp(-volume->distance_at(p), 0.0, max_depth); };
  }

  // Signed distance to another input's surface (mm, negative inside), exact from -inside_mm to outside_mm.
  Field signed_distance_in(const std::string& name, double inside, double outside) const {
    // Fine enough to place nodes within a few percent of a cell, no finer than the part's voxels.
    const double range = std::max(inside, outside);
    VolumeOptions wide;
    wide.voxel_size_mm = std::max(vopt_.voxel_size_mm, range / 20);
    wide.half_band_voxels = range / wide.voxel_size_mm + 2;
    auto volume = std::make_shared<Volume>(voxelize(geometry_of(name), wide));
    return [volume](const Vec3d& p) { return volume->distance_at(p); };
  }

  double volume_of(const std::string& name) const { return voxelize(geometry_of(name), vopt_).voxel_volume_mm3(); }

  // A hull must be a valid closed solid (closed, manifold, outward, no self-intersections) unless
  // the recipe asks for explicit repairs; a broken one is an error that says what is wrong.
  TriMesh checked_hull(TriMesh mesh, const MeshRepair& repair, const std::string& what) const {
    MeshCheckReport r = check_mesh(mesh);
    if (r.valid()) return mesh;
    if (repair.any()) {
      RepairOptions options;
      options.weld_mm = repair.weld_mm;
      options.reorient = repair.reorient;
      options.close_gaps_mm = repair.close_gaps_mm;
      mesh = repair_mesh(mesh, options, recipe_.voxel_size_mm);
      r = check_mesh(mesh);
      if (r.valid()) return mesh;
    }
    // Overlapping shells and crossings are resolved as a union by the level set when allowed.
    if (repair.allow_overlaps && r.closed() && r.non_manifold_edges == 0 && r.triangles > 0 && r.non_finite_vertices == 0)
      return mesh;
    std::string problems;
    for (const std::string& p : r.problems()) problems += (problems.empty() ? "" : "; ") + p;
    throw InvalidInput(what + " is not a valid closed solid: " + problems + (repair.any() ? " (after the repairs asked for)" : "") +
                       ". Repair it explicitly with \"repair\": {\"weld_mm\", \"reorient\", \"close_gaps_mm\", "
                       "\"allow_overlaps\"}, or thicken an open surface with type \"surface\"");
  }

  // The source's mesh, read (files relative to the recipe's folder) and placed; `what` receives the
  // name messages about it use.
  TriMesh mesh_of(const MeshSource& source, std::string& what) const {
    TriMesh mesh;
    if (source.file.empty()) {
      what = where();
      mesh = source.inline_mesh;
    } else {
      fs::path file(source.file);
      if (file.is_relative()) file = fs::path(recipe_.file).parent_path() / file;
      const std::string at = where() + ".file";
      std::error_code ec;
      if (!fs::exists(file, ec)) throw IoError(at + ": " + file.string() + " does not exist");
      ReadOptions read;
      if (context_.max_memory_bytes) read.max_memory_bytes = context_.max_memory_bytes;
      try {
        mesh = read_mesh(file.string(), read);
      } catch (const InvalidInput& e) {
        throw InvalidInput(at + ": " + e.what());
      } catch (const IoError& e) {
        throw IoError(at + ": " + e.what());
      } catch (const ResourceLimit& e) {
        throw ResourceLimit(at + ": " + e.what());
      }
      what = at + ": " + file.string();
    }
    for (Vec3d& p : mesh.positions_mm) p = p * source.scale + source.translate_mm;
    return mesh;
  }

  void add(const SphereInput& s) {
    out_.geometry.spheres.centers_mm.push_back(s.center_mm);
    out_.geometry.spheres.radii_mm.push_back(s.radius_mm);
  }

  void add(const SpheresInput& s) {
    out_.geometry.spheres.centers_mm = s.centers_mm;
    out_.geometry.spheres.radii_mm = s.radii_mm;
  }

  void add(const CapsuleInput& c) {
    out_.geometry.tubes.tubes.push_back(Tube{{c.a_mm, c.b_mm}, {c.radius_mm, c.radius_b_mm}});
  }

  void add(const TubesInput& t) { out_.geometry.tubes.tubes = t.polylines; }

  void add(const BoxInput& b) {
    Shape s;
    s.kind = Shape::Kind::kBox;
    s.center_mm = b.center_mm;
    s.half_size_mm = b.half_size_mm;
    out_.geometry.shapes.push_back(s);
  }

  void add(const CylinderInput& c) {
    Shape s;
    s.kind = Shape::Kind::kCylinder;
    s.center_mm = c.center_mm;
    s.axis = c.axis;
    s.radius_mm = c.radius_mm;
    s.height_mm = c.height_mm;
    out_.geometry.shapes.push_back(s);
  }

  void add(const TorusInput& t) {
    Shape s;
    s.kind = Shape::Kind::kTorus;
    s.center_mm = t.center_mm;
    s.axis = t.axis;
    s.radius_mm = t.major_radius_mm;
    s.minor_radius_mm = t.minor_radius_mm;
    out_.geometry.shapes.push_back(s);
  }

  void add(const RegionInput& r) { out_.geometry.regions.push_back(r.region); }

  void add(const MeshInput& m) {
    std::string what;
    TriMesh mesh = mesh_of(m.source, what);
    out_.geometry.solids.push_back(checked_hull(std::move(mesh), m.repair, what));
  }

  void add(const SurfaceInput& s) {
    std::string what;
    TriMesh mesh = mesh_of(s.source, what);
    out_.geometry.surfaces.push_back(ThickSurface{std::move(mesh), s.thickness_mm});
  }

  void add(const LatticeInput& l) {
    if (!l.fit_to) {
      try {
        out_.geometry.tubes = lattice_tubes(l.box, l.lattice);
      } catch (const InvalidInput& e) {
        fail("", e.what());
      }
      return;
    }
    const std::string& hull = *l.fit_to;
    HullFields fields;
    if (l.lattice.grade.kind == GradeField::Kind::kDepth) fields.depth_mm = depth_in(hull, l.lattice.grade.depth_mm);
    if (l.lattice.layout == LatticeOptions::Layout::kConforming) {
      // Nodes up to a cell outside, and the inset surface, must lie in the field's band; nothing in
      // the hull is deeper than half its box's smallest side.
      const double period = l.lattice.period_mm;
      const Vec3d size = box_of(hull).size();
      const double deepest = 0.5 * std::min({size.x, size.y, size.z});
      if (l.lattice.conform_inset_mm >= deepest)
        fail("inset_mm", "no strut is left: an inset of " + message_number(l.lattice.conform_inset_mm) +
                             " mm is deeper than anything in \"" + hull + "\" (at most " + message_number(deepest) + " mm)");
      fields.signed_distance_mm = signed_distance_in(hull, l.lattice.conform_inset_mm + period, period);
    }
    try {
      out_.geometry.tubes = lattice_tubes(box_of(hull), l.lattice, fields);
    } catch (const InvalidInput& e) {
      throw InvalidInput(where() + ": " + e.what());
    }
  }

  void add(const CifsInput& c) {
    auto attractor = [&](const cifs::Cifs& placed) {
      try {
        cifs::SolidOptions solid = c.solid;
        solid.voxel_size_mm = vopt_.voxel_size_mm;
        return cifs::attractor_geometry(placed, c.level, solid);
      } catch (const InvalidInput& e) {
        throw InvalidInput(where() + ": " + e.what());
      } catch (const ResourceLimit& e) {
        throw ResourceLimit(where() + ": " + e.what());
      }
    };
    // Scaled (uniformly) and moved so the attractor's box fits the other input's, centred.
    const cifs::Cifs placed = c.fit_to ? cifs::fit_to_box(c.system, box_of(*c.fit_to)) : c.system;
    out_.geometry = attractor(placed);
    if (!c.support) return;
    // The shell's own tree: the branches' tops are the shell's pieces of the same level.
    cifs::Cifs tree;
    try {
      tree = cifs::support_tree(placed, *c.support);
    } catch (const InvalidInput& e) {
      throw InvalidInput(where() + ": support: " + e.what());
    }
    cifs::SolidOptions cells;
    cells.as = cifs::SolidOptions::As::kCells;
    cells.voxel_size_mm = vopt_.voxel_size_mm;
    GeometrySet branches;
    try {
      branches = cifs::attractor_geometry(tree, c.level, cells);
    } catch (const InvalidInput& e) {
      throw InvalidInput(where() + ": support: " + e.what());
    }
    for (GeometryStream& s : branches.streams) out_.geometry.streams.push_back(std::move(s));
  }

  void add(const CurveInput& c) {
    using Surface = CurveInput::Surface;
    curves::SurfaceMap map;
    bool on_cube = false;
    switch (c.surface) {
      case Surface::kPlane: map = curves::plane_map(); break;
      case Surface::kSphere: map = curves::sphere_map(); break;
      case Surface::kCylinder: map = curves::cylinder_map(); break;
      case Surface::kTorus: map = curves::torus_map(); break;
      case Surface::kCone: map = curves::cone_map(); break;
      case Surface::kCube: on_cube = true; break;
      case Surface::kBspline: map = curves::bspline_map(c.patch); break;
      case Surface::kMesh: {
        // A disk-like patch of a mesh, flattened onto the square.
        const std::string file = (fs::path(recipe_.file).parent_path() / c.mesh_file).string();
        try {
          map = mesh_patch_map(read_mesh(file), file);
        } catch (const InvalidInput& e) {
          throw InvalidInput(where() + ": " + e.what());
        } catch (const IoError& e) {
          throw IoError(where() + ": " + e.what());
        }
        break;
      }
    }
    try {
      // Points are counted against the budget as they are made (about 128 bytes each, with the tubes
      // made of them), so that a tiny tolerance_mm is refused before it exhausts the memory.
      curves::SweepOptions options = c.sweep;
      options.map.max_points = std::min<uint64_t>(options.map.max_points, context_.max_memory_bytes / 128);
      curves::Sweep sweep = curves::sweep_curves(options, map, on_cube);
      out_.report = CurveReport{sweep.tubes.tubes.size(), sweep.segments};
      out_.geometry.tubes = std::move(sweep.tubes);
      out_.geometry.surfaces = std::move(sweep.base);
    } catch (const InvalidInput& e) {
      throw InvalidInput(where() + ": " + e.what());
    } catch (const ResourceLimit& e) {
      throw ResourceLimit(where() + ": " + e.what());
    }
  }

  void add(const FillMotifsInput& f) {
    fill::MotifSolidOptions solid = f.solid;
    std::vector<fill::Placement2> placements;
    try {
      // The colour class of each motif of the fill (all its images share it), when only one is kept.
      auto kept = [&](const fill::FillResult2& r) {
        std::vector<uint8_t> keep(r.motifs.size(), 1);
        if (f.color_class) {
          const std::vector<int> colors = fill::motif_colors(r, f.color_class->by, f.color_class->classes, f.fill.seed);
          for (size_t i = 0; i < keep.size(); ++i) keep[i] = colors[i] == f.color_class->keep;
        }
        return keep;
      };
      if (!f.wallpaper) {
        fill::FillResult2 r = fill::fill_region(f.region, f.motif, f.fill);
        const std::vector<uint8_t> keep = kept(r);
        for (size_t i = 0; i < r.motifs.size(); ++i)
          if (keep[i]) placements.push_back(r.motifs[i]);
        out_.report = MotifFillReport{placements.size(), std::nullopt, r.fill_fraction, r.stop_reason};
      } else {
        fill::WallpaperFill pattern;
        try {
          pattern = fill::fill_wallpaper(f.group, f.lattice, f.motif, f.fill, f.policy);
        } catch (const InvalidInput& e) {
          if (names_recipe(e)) throw;
          fail("wallpaper", e.what());
        }
        std::vector<uint32_t> orbits;
        const std::vector<fill::Placement2> all = fill::replicate(pattern, f.cells_u, f.cells_v, &orbits);
        const std::vector<uint8_t> keep = kept(pattern.fundamental);
        for (size_t i = 0; i < all.size(); ++i)
          if (keep[orbits[i]]) placements.push_back(all[i]);
        size_t fundamental = 0;
        for (uint8_t k : keep) fundamental += k;
        out_.pattern = std::make_shared<const fill::WallpaperFill>(pattern);
        out_.report = MotifFillReport{placements.size(), fundamental, pattern.fundamental.fill_fraction,
                                      pattern.fundamental.stop_reason};
        if (f.wrap_depth_mm > 0) {
          // The pattern's period along x, times the cells, is the circumference.
          const fill::Lattice& l = pattern.lattice;
          if (std::abs(l.a.y) > 1e-9 * std::abs(l.a.x))
            fail("wallpaper.a_mm", "to wrap around a cylinder the lattice vector a must lie along x ([a, 0])");
          solid.wrap_radius_mm = f.cells_u * std::abs(l.a.x) / (2 * kPi);
          solid.height_mm = f.wrap_depth_mm;
        }
      }
    } catch (const InvalidInput& e) {
      if (names_recipe(e)) throw;
      fail("", e.what());
    }
    if (placements.empty() && f.color_class)
      fail("color_class", "no motif has colour class " + std::to_string(f.color_class->keep) + " of " +
                              std::to_string(f.color_class->classes));
    if (placements.empty()) fail("", "no motif could be placed");
    out_.geometry = fill::motif_solids(f.motif, placements, solid);
  }

  void add(const FillSpheresInput& f) {
    using Motif = FillSpheresInput::Motif;
    std::unique_ptr<fill::Motif3> polyhedron;
    if (f.motif == Motif::kCube) polyhedron = std::make_unique<fill::Motif3>(fill::cube_motif());
    else if (f.motif == Motif::kTetrahedron) polyhedron = std::make_unique<fill::Motif3>(fill::tetrahedron_motif());
    else if (f.motif == Motif::kOctahedron) polyhedron = std::make_unique<fill::Motif3>(fill::octahedron_motif());
    auto place = [&](const fill::SignedDistance3& sd, const Box3& box, double volume) {
      if (polyhedron) {
        try {
          fill::FillResult3P r = fill::fill_polyhedra(sd, box, volume, *polyhedron, f.fill, f.random_rotation);
          out_.report = VolumeFillReport{true, r.motifs.size(), r.fill_fraction, r.stop_reason};
          ConvexCells cells;
          cells.corners_per_cell = int(polyhedron->vertices.size());
          cells.faces = polyhedron->faces;
          for (const fill::Placement3& p : r.motifs)
            for (const Vec3d& v : fill::placed_vertices(*polyhedron, p)) cells.corners_mm.push_back(v);
          if (cells.corners_mm.empty()) throw InvalidInput("no polyhedron could be placed");
          out_.geometry.cells.push_back(std::move(cells));
        } catch (const InvalidInput& e) {
          throw InvalidInput(where() + ": " + e.what());
        }
        return;
      }
      try {
        fill::FillResult3 r = fill::fill_spheres(sd, box, volume, f.fill);
        out_.report = VolumeFillReport{false, r.centers_mm.size(), r.fill_fraction, r.stop_reason};
        out_.geometry.spheres.centers_mm = std::move(r.centers_mm);
        out_.geometry.spheres.radii_mm = std::move(r.radii_mm);
      } catch (const InvalidInput& e) {
        throw InvalidInput(where() + ": " + e.what());
      }
      if (out_.geometry.spheres.centers_mm.empty()) throw InvalidInput(where() + ": no sphere could be placed");
    };
    switch (f.region) {
      case FillSpheresInput::Region::kBox: {
        const Vec3d s = f.box.size();
        place(fill::box_region_distance(f.box), f.box, s.x * s.y * s.z);
        return;
      }
      case FillSpheresInput::Region::kSphere: {
        const Vec3d c = f.sphere_center_mm;
        const double r = f.sphere_radius_mm;
        Box3 box;
        box.expand(c - Vec3d{r, r, r});
        box.expand(c + Vec3d{r, r, r});
        place(fill::sphere_region_distance(c, r), box, 4.0 / 3.0 * kPi * r * r * r);
        return;
      }
      case FillSpheresInput::Region::kFitTo: {
        const Box3 box = box_of(f.fit_to);
        const double volume = volume_of(f.fit_to);
        // The field must be exact as deep as the largest sphere's radius plus its wall.
        const double v0 = volume / (fill::hurwitz_zeta(f.fill.c, f.fill.N) * std::pow(f.fill.N, f.fill.c));
        // The largest motif's reach from its centre: a sphere's radius, a polyhedron's bounding radius.
        const double r0 = polyhedron ? std::cbrt(v0) * polyhedron->bounding_radius : std::cbrt(3 * v0 / (4 * kPi));
        place(signed_distance_in(f.fit_to, r0 + f.fill.boundary_gap_mm + f.fill.gap_mm + 1e-3, 1e-3 + 0.01 * r0), box,
              volume);
        return;
      }
    }
  }

  // The partition every Voronoi input starts from: rules with scaled children and one generated level.
  struct Partition {
    voronoi::TorusPlacement place;
    voronoi::Rules rules;
    voronoi::Level level;
  };

  Partition partition(const VoronoiPartition& p, bool keep_unwrapped) const {
    Partition part;
    part.place = voronoi::TorusPlacement{p.dimension, p.period_mm, p.origin_mm};
    const std::vector<std::vector<double>> points =
        p.points.empty() ? voronoi::random_points(p.dimension, p.random_points, p.seed) : p.points;
    try {
      voronoi::RulesOptions options;
      options.children = voronoi::RulesOptions::Children::kScaled;
      part.rules = voronoi::make_rules(p.dimension, p.d, points, options);
      part.level = voronoi::generate_level(part.rules, p.level, keep_unwrapped);
    } catch (const InvalidInput& e) {
      fail("", e.what());
    } catch (const ResourceLimit& e) {
      throw ResourceLimit(where() + ": " + e.what());
    }
    return part;
  }

  static VoronoiPartition with_level(VoronoiPartition p, int level) {
    p.level = level;
    return p;
  }

  // A keep-flag per colour: the 1-based colours listed, or every one.
  static std::vector<char> kept(const std::vector<int>& colours, size_t m) {
    std::vector<char> keep(m, colours.empty() ? 1 : 0);
    for (int c : colours) keep[size_t(c - 1)] = 1;
    return keep;
  }

  static VoronoiWallsReport walls_report(const Partition& part, const voronoi::Walls& walls) {
    const double period = part.place.period_mm;
    const double unit = part.place.dimension == 2 ? period : period * period;
    VoronoiWallsReport r;
    r.dimension = part.place.dimension;
    r.points = walls.points;
    r.boundary_generators = walls.boundary_generators;
    r.wall_facets = walls.facets.size();
    r.wall_measure = walls.measure * unit;
    return r;
  }

  void add(const VoronoiSpheresInput& v) {
    const Partition part = partition(v.partition, false);
    const int n = part.place.dimension;
    const std::array<int, 3>& tiles = v.tiles;
    const std::vector<char> keep = kept(v.colours, part.rules.points.size());
    const voronoi::Level& points_k = part.level;
    const size_t total = points_k.points.size() * size_t(tiles[0]) * size_t(tiles[1]) * size_t(tiles[2]);
    if (total > 20'000'000) throw ResourceLimit(where() + ": more than 20 000 000 spheres");
    SphereSet& s = out_.geometry.spheres;
    s.radii_mm = {v.radius_mm};
    for (int tz = 0; tz < tiles[2]; ++tz)
      for (int ty = 0; ty < tiles[1]; ++ty)
        for (int tx = 0; tx < tiles[0]; ++tx)
          for (size_t i = 0; i < points_k.points.size(); ++i) {
            if (!keep[size_t(points_k.colours[i])]) continue;
            const auto& p = points_k.points[i];
            s.centers_mm.push_back(part.place.to_mm(tx + p[0], ty + p[1], n == 3 ? tz + p[2] : 0.0));
          }
    out_.report = VoronoiSpheresReport{points_k.points.size(), s.centers_mm.size()};
  }

  // `refine` of voronoi_tiles (the foam's is voronoi::refined_walls): the partition's fractal cells, each
  // replaced by its children while the field at its generator asks for it, every tile drawn with `level` levels
  // of detail; part.level's colours become the tiles, with the unwrapped positions the compact tiles are drawn
  // at. Returns the tiles' starting colours and counts per level. The field is read at each tile's generator
  // where the compact tile is drawn (its unwrapped position).
  voronoi::RefinedLevel refine(Partition& part, const VoronoiPartition& partition, const GradeField& field,
                               int levels) {
    const voronoi::TorusPlacement& place = part.place;
    try {
      voronoi::RefinedLevel refined = voronoi::refine_level(
          part.rules, partition.level, levels,
          [&](const std::vector<double>& x, int l) {
            const Vec3d p = place.to_mm(x[0], x[1], place.dimension == 3 ? x[2] : 0.0);
            return field.at(p) > double(l + 1) / double(levels + 1);
          },
          true);
      part.level = std::move(refined.level);
      return refined;
    } catch (const ResourceLimit& e) {
      throw ResourceLimit(where() + ".refine: " + e.what());
    }
  }

  // Compact tiles: each kept colour's fractal cell around its starting point, with a clearance to the others;
  // with `refine`, each of its refined tiles.
  void add(const VoronoiTilesInput& v) {
    Partition part = partition(v.refine_levels ? with_level(v.partition, 0) : v.partition, !v.refine_levels);
    const std::vector<char> keep = kept(v.colours, part.rules.points.size());
    // The tiles drawn and the starting colour of each: without refinement the m fractal cells.
    std::vector<int> tile_colour(keep.size());
    for (size_t c = 0; c < keep.size(); ++c) tile_colour[c] = int(c);
    std::vector<int> tiles_per_level;
    if (v.refine_levels) {
      voronoi::RefinedLevel refined = refine(part, v.partition, v.refine, v.refine_levels);
      tile_colour = std::move(refined.tile_colour);
      tiles_per_level = std::move(refined.tiles_per_level);
    }
    std::vector<char> keep_tile(tile_colour.size());
    for (size_t t = 0; t < tile_colour.size(); ++t) keep_tile[t] = keep[size_t(tile_colour[t])];
    size_t pieces = 0;
    for (const voronoi::ConvexPiece& piece :
         voronoi::tile_pieces(part.rules, part.level, keep_tile, v.clearance_mm / 2 / part.place.period_mm)) {
      voronoi::add_piece(part.place, piece.faces, v.thickness_mm, out_.geometry);
      ++pieces;
    }
    VoronoiWallsReport report = walls_report(part, voronoi::extract_walls(part.rules, part.level));
    report.pieces = pieces;
    report.clearance_mm = v.clearance_mm;
    report.tiles_per_level = tiles_per_level;
    out_.report = report;
  }

  // Foam: the walls between colours thickened, repeated over whole periods (clip it with an intersection). With
  // `refine`, every copy of a tile is refined where it lies (the field read at its generator there).
  void add(const VoronoiFoamInput& v) {
    Partition part = partition(v.refine_levels ? with_level(v.partition, 0) : v.partition, false);
    const voronoi::TorusPlacement& place = part.place;
    // The periods drawn: the tiles, or every period that meets the covered input's box (walls reach a little
    // past their own period).
    std::array<int, 3> a{0, 0, 0}, b = v.tiles;
    if (v.cover) {
      const Box3 box = box_of(*v.cover);
      const Vec3d lo = (box.min - place.origin_mm) / place.period_mm;
      const Vec3d hi = (box.max - place.origin_mm) / place.period_mm;
      for (int k = 0; k < 3; ++k)
        if (!(std::fabs(lo[k]) < 1e6 && std::fabs(hi[k]) < 1e6))
          throw ResourceLimit(where() + ".cover: its box spans more than a million periods; use a larger period_mm");
      a = {int(std::floor(lo.x)) - 1, int(std::floor(lo.y)) - 1, int(std::floor(lo.z)) - 1};
      b = {int(std::ceil(hi.x)) + 1, int(std::ceil(hi.y)) + 1, int(std::ceil(hi.z)) + 1};
    }
    if (place.dimension == 2) {
      a[2] = 0;
      b[2] = 1;
    }
    const double periods = double(b[0] - a[0]) * (b[1] - a[1]) * (b[2] - a[2]);
    if (v.refine_levels) {
      voronoi::RefinedWalls refined;
      const int levels = v.refine_levels;
      try {
        refined = voronoi::refined_walls(part.rules, v.partition.level, levels, a, b,
                                         [&](const std::vector<double>& x, int l) {
                                           const Vec3d p = place.to_mm(x[0], x[1], place.dimension == 3 ? x[2] : 0.0);
                                           return v.refine.at(p) > double(l + 1) / double(levels + 1);
                                         });
      } catch (const InvalidInput& e) {
        fail("refine", e.what());
      } catch (const ResourceLimit& e) {
        throw ResourceLimit(where() + (v.cover ? ".cover: " : ".refine: ") + e.what());
      }
      VoronoiWallsReport report = walls_report(part, refined.walls);
      report.tiles_per_level = refined.tiles_per_level;
      out_.report = report;
      voronoi::add_foam(place, refined.walls, {0, 0, 0}, {1, 1, 1}, v.wall_mm, v.thickness_mm, out_.geometry);
      return;
    }
    const voronoi::Walls walls = voronoi::extract_walls(part.rules, part.level);
    out_.report = walls_report(part, walls);
    part.level = voronoi::Level();  // the walls are all that is needed from here on
    if (periods * double(walls.facets.size()) > 5e7)
      throw ResourceLimit(where() + (v.cover ? ".cover: covering it takes " : ": the tiles take ") +
                          std::to_string(int64_t(periods)) + " periods of " + std::to_string(walls.facets.size()) +
                          " walls; use a larger period_mm");
    voronoi::add_foam(place, walls, a, b, v.wall_mm, v.thickness_mm, out_.geometry);
  }

  void add(const BcifsPlateInput& p) {
    const bcifs::Plate plate = build_plate(p, recipe_.file, in_.json_path);
    const bcifs::PlateOptions& o = plate.options;
    Region2 region;
    region.loops_mm = bcifs::plate_loops(plate, o.level);
    region.height_mm = o.thickness_mm;
    region.origin_mm = o.origin_mm;
    BcifsPlateReport report;
    for (const auto& loop : region.loops_mm) {
      const double a = signed_area(loop);
      report.area_mm2 += a;
      report.holes += a < 0;
    }
    for (size_t f = 0; f < o.assembly.faces.size(); ++f) {
      const int type = plate.rules.roots[f];
      const bcifs::Lacunarity l = bcifs::lacunarity(plate.rules, type, o.level);
      report.faces.push_back({type, l.subfaces.back(), l.lacunas.back(), l.limit});
    }
    report.level = o.level;
    report.face_types = plate.rules.rules.size();
    report.loops = region.loops_mm.size();
    out_.report = report;
    out_.plate = std::make_shared<const bcifs::Plate>(plate);
    out_.geometry.regions.push_back(std::move(region));
  }

  // A polyhedral cell whose faces are lacunar faces: every face realized in its own plane (its corners as the
  // control polygon) and extruded inwards by thickness_mm. All edges have one type, so neighbouring faces
  // subdivide their shared edge the same way and their notches meet.
  void add(const BcifsCellInput& c) {
    const std::vector<std::vector<Vec3d>> faces = bcifs::cell_faces(c.cell, c.edge_mm);
    std::vector<bcifs::FaceType> types;
    for (const auto& f : faces) types.push_back({std::vector<bcifs::EdgeType>(f.size(), c.edge), c.params, c.algorithm, 1});
    bcifs::RuleSet rules;
    try {
      rules = bcifs::build_rules(types);
    } catch (const InvalidInput& e) {
      fail("", e.what());
    }
    BcifsCellReport report;
    for (size_t k = 0; k < faces.size(); ++k) {
      const auto& f = faces[k];
      // The face's plane: origin at its first corner, u along its first edge, v = n x u.
      Vec3d n{0, 0, 0};
      for (size_t j = 0; j < f.size(); ++j) n += cross(f[j], f[(j + 1) % f.size()]);
      n = n / norm(n);
      const Vec3d u = (f[1] - f[0]) / norm(f[1] - f[0]);
      const Vec3d v = cross(n, u);
      std::vector<Vec2d> control;
      for (const Vec3d& p : f) control.push_back({dot(p - f[0], u), dot(p - f[0], v)});
      // The type's canonical rotation of a boundary with one edge type is the boundary itself.
      Region2 region;
      region.loops_mm =
          bcifs::union_loops(bcifs::polygons_of(bcifs::realize(rules, rules.roots[k], control, c.level, c.options)));
      for (const auto& loop : region.loops_mm) {
        const double a = signed_area(loop);
        report.face_area_mm2 += a;
        report.holes += a < 0;
      }
      region.origin_mm = c.center_mm + f[0] - n * c.thickness_mm;  // the slab spans [-thickness, 0] along n: inwards
      region.axis_u = u;
      region.axis_v = v;
      region.height_mm = c.thickness_mm;
      out_.geometry.regions.push_back(std::move(region));
    }
    report.faces = faces.size();
    report.face_types = rules.rules.size();
    out_.report = report;
  }

  // Cells subdivided in 3D: the level's sub-cells as convex pieces (lacunas and tunnels are what is left out).
  void add(const BcifsVolumeInput& v) {
    const bcifs::VolumeRules rules = volume_rules(v.spec);
    const double cells = bcifs::volume_cells(rules, v.level);
    if (cells > bcifs::kMaxVolumeCells)
      throw ResourceLimit(where() + ".level: level " + std::to_string(v.level) + " has " + message_number(cells) +
                          " cells, more than " + message_number(bcifs::kMaxVolumeCells) + "; use a lower level");
    BcifsVolumeReport report;
    report.r_limit = bcifs::volume_lacunarity(rules, rules.roots[0], v.level).limit;
    add_cells(rules, v.spec, v.level, v.options, report);
    out_.report = report;
    out_.volume = std::make_shared<const BcifsVolumeInput>(v);
  }

  // The rules of a volume's cells; their errors name this input.
  bcifs::VolumeRules volume_rules(const bcifs::VolumeSpec& spec) const {
    try {
      return bcifs::build_volume_rules(spec);
    } catch (const InvalidInput& e) {
      fail("", e.what());
    } catch (const ResourceLimit& e) {
      throw ResourceLimit(where() + ": " + e.what());
    }
  }

  // The cells realized at `level` into this input's geometry as convex pieces, and their counts in the report.
  void add_cells(const bcifs::VolumeRules& rules, const bcifs::VolumeSpec& spec, int level,
                 const bcifs::VolumeGeometryOptions& options, BcifsVolumeReport& report) {
    const bcifs::VolumeLevel cells = bcifs::realize_volume(rules, spec, level, options);
    report.level = level;
    report.cells = cells.cells.size();
    report.lacunas = bcifs::volume_lacunas(rules, level);
    report.cell_types = rules.cells.size();
    report.face_types = rules.faces.rules.size();
    report.shared_faces = rules.shared.size();
    for (const bcifs::VolumeCell& c : cells.cells) report.volume_mm3 += bcifs::cell_volume(c, spec);
    for (ConvexCells& pieces : bcifs::convex_pieces(cells, spec)) {
      report.pieces += pieces.size();
      out_.geometry.cells.push_back(std::move(pieces));
    }
  }

  // A hull filled with lacunar cells: a grid of cubes of cell_mm, each split into six tetrahedra around its
  // diagonal (Kuhn's split: neighbours split their common face alike), the tetrahedra that reach into the hull's
  // inset (skin_mm in) kept and their outside corners moved onto the inset surface, so the cells conform to it.
  // Tetrahedra keep every face planar however their corners move (a moved hexahedron would not). Faces two
  // tetrahedra share are shared cells' faces, so the structure is consistent across them; delays by size give
  // every cell lacunas of about one size. A cell grade halves the tetrahedra (Maubach's bisection, which keeps
  // them conforming) down to min_cell_mm where its field is 1.
  void add(const BcifsInfillInput& b) {
    const double h = b.cell_mm;
    VolumeOptions coarse;
    coarse.voxel_size_mm = std::max(vopt_.voxel_size_mm, h / 20);
    // A kept tetrahedron's outside corner lies within a cube's diagonal of an inside one: the band reaches that
    // far past the inset, so every corner to move sees its true distance.
    coarse.half_band_voxels = (b.skin_mm + h * std::sqrt(3.0)) / coarse.voxel_size_mm + 3;
    Volume inset = voxelize(geometry_of(b.hull), coarse);
    if (b.skin_mm > 0) inset = offset(inset, -b.skin_mm);
    if (inset.empty()) fail("skin_mm", "the hull is thinner than twice the skin: nothing is left to fill");
    const Box3 box = inset.bounding_box();
    std::array<int64_t, 3> lo{}, count{};
    for (int a = 0; a < 3; ++a) {
      lo[size_t(a)] = int64_t(std::floor(box.min[a] / h)) - 1;
      count[size_t(a)] = int64_t(std::ceil(box.max[a] / h)) + 2 - lo[size_t(a)];
    }
    if (double(count[0]) * double(count[1]) * double(count[2]) > 4e6)
      fail("cell_mm", "cells of " + message_number(h) + " mm make more than 4 000 000 grid corners in the hull; "
                      "use larger cells");
    auto index = [&](int64_t i, int64_t j, int64_t k) { return uint32_t((k * count[1] + j) * count[0] + i); };
    const size_t corners = size_t(count[0] * count[1] * count[2]);
    std::vector<Vec3d> point(corners);
    std::vector<double> distance(corners);
    for (int64_t k = 0; k < count[2]; ++k)
      for (int64_t j = 0; j < count[1]; ++j)
        for (int64_t i = 0; i < count[0]; ++i) {
          const size_t v = index(i, j, k);
          point[v] = Vec3d{double(lo[0] + i), double(lo[1] + j), double(lo[2] + k)} * h;
          distance[v] = inset.distance_at(point[v]);
        }
    // Kuhn's six tetrahedra of every cube, bisected conformingly (infill/bisection.h) where the cell grade asks
    // for smaller cells.
    std::vector<GridTet> tets;
    for (int64_t k = 0; k + 1 < count[2]; ++k)
      for (int64_t j = 0; j + 1 < count[1]; ++j)
        for (int64_t i = 0; i + 1 < count[0]; ++i)
          for (const GridTet& t : kuhn_tetrahedra([&](int c) { return index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)); }))
            tets.push_back(t);
    if (b.cell_grade.kind != GradeField::Kind::kNone) {
      const Field depth = b.cell_grade.kind == GradeField::Kind::kDepth ? depth_in(b.hull, b.cell_grade.depth_mm) : Field{};
      const double octaves = std::log2(h / b.min_cell_mm);
      // Three bisections for every octave the cell size falls at a point.
      refine_grid_tets(
          point, distance, tets, [&](const Vec3d& p) { return int(std::lround(3 * octaves * b.cell_grade.at(p, depth))); },
          [&](const Vec3d& p) { return inset.distance_at(p); },
          [&](size_t count_now) {
            if (double(count_now) > bcifs::kMaxVolumeCells)
              fail("cell_grade", "cells down to " + message_number(b.min_cell_mm) + " mm make more than " +
                                     message_number(bcifs::kMaxVolumeCells) + " tetrahedra; use a larger min_cell_mm");
          });
    }
    std::vector<std::array<uint32_t, 4>> kept;
    std::vector<char> moves(point.size(), 0);
    for (const GridTet& t : tets) {
      bool inside = false;
      for (uint32_t q : t.v) inside = inside || distance[q] < 0;
      if (!inside) continue;
      kept.push_back(t.v);
      for (uint32_t q : t.v)
        if (distance[q] >= 0) moves[q] = 1;
    }
    // Every tetrahedron makes at least one cell at every level: refuse before building millions of them.
    if (double(kept.size()) > bcifs::kMaxVolumeCells)
      throw ResourceLimit(where() + ".cell_mm: cells of " + message_number(h) + " mm make " +
                          message_number(double(kept.size())) + " tetrahedra in the hull, more than " +
                          message_number(bcifs::kMaxVolumeCells) + "; use larger cells");
    // Outside corners onto the inset surface: Newton steps along the distance's gradient.
    const double step = coarse.voxel_size_mm;
    std::vector<Vec3d> moved = point;
    for (size_t v = 0; v < point.size(); ++v) {
      if (!moves[v]) continue;
      Vec3d p = point[v];
      for (int it = 0; it < 4; ++it) {
        const double d = inset.distance_at(p);
        const Vec3d g{inset.distance_at(p + Vec3d{step, 0, 0}) - inset.distance_at(p - Vec3d{step, 0, 0}),
                      inset.distance_at(p + Vec3d{0, step, 0}) - inset.distance_at(p - Vec3d{0, step, 0}),
                      inset.distance_at(p + Vec3d{0, 0, step}) - inset.distance_at(p - Vec3d{0, 0, step})};
        const double g2 = dot(g, g) / (4 * step * step);
        if (!(g2 > 0.25)) break;  // no clear direction (a ridge of the distance): leave it
        p = p - g * (d / (2 * step) / g2);
      }
      moved[v] = p;
      // One that did not reach the surface (a ridge of the distance) would leave its cells sticking out.
      if (inset.distance_at(p) > step) moves[v] = 2;
    }
    bcifs::VolumeSpec spec;
    spec.interior = b.interior;
    std::vector<double> sizes;
    for (const auto& t : kept) {
      if (moves[t[0]] == 2 || moves[t[1]] == 2 || moves[t[2]] == 2 || moves[t[3]] == 2) continue;
      bcifs::CellSpec c;
      for (size_t q : t) c.shape.corners_mm.push_back(moved[q]);
      const auto signed_volume = [](const std::vector<Vec3d>& p) {
        return dot(p[1] - p[0], cross(p[2] - p[0], p[3] - p[0])) / 6;
      };
      std::vector<Vec3d> before;
      for (size_t q : t) before.push_back(point[q]);
      const double was = signed_volume(before), now = signed_volume(c.shape.corners_mm);
      // Flattened or turned over by the move: dropped (the skin closes what is left there).
      if (!(now * was > 0) || std::fabs(now) < 0.05 * std::fabs(was)) continue;
      if (now < 0) std::swap(c.shape.corners_mm[1], c.shape.corners_mm[2]);
      // Positively oriented (corner 3 on the side the normal of 0, 1, 2 points to): these run outward.
      c.shape.faces = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
      sizes.push_back(std::cbrt(6 * std::sqrt(2.0) * std::fabs(now)));  // the edge of a regular tetrahedron that large
      bcifs::set_uniform_faces(c, b.face, b.plain);
      spec.cells.push_back(std::move(c));
    }
    if (spec.cells.empty()) fail("cell_mm", "the inset hull holds no cell");
    // The levels a grade takes away per tetrahedron, read at its corners' average (as a lattice's level grade).
    std::vector<int> lowered(spec.cells.size(), 0);
    if (b.grade.kind != GradeField::Kind::kNone) {
      const Field depth = b.grade.kind == GradeField::Kind::kDepth ? depth_in(b.hull, b.grade.depth_mm) : Field{};
      for (size_t c = 0; c < spec.cells.size(); ++c) {
        Vec3d centre{0, 0, 0};
        for (const Vec3d& p : spec.cells[c].shape.corners_mm) centre += p * 0.25;
        const double g = b.grade.at(centre, depth);
        int raised = 0;
        for (int k = 0; k < b.grade_levels; ++k) raised += g > double(k + 1) / double(b.grade_levels + 1);
        lowered[c] = b.grade_levels - raised;
      }
    }
    std::vector<int> delays(spec.cells.size(), 1);
    if (b.equal_lacunas) {
      // What a level does to a full cell inside the hull (the largest: one the surface did not move).
      const size_t reference = size_t(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
      const double shrink = bcifs::level_shrink(spec, int(reference), b.options);
      delays = bcifs::delays_for_sizes(sizes, b.level, shrink);
    }
    // A lower level is a longer delay: the faces between cells of different levels stay consistent.
    for (size_t c = 0; c < spec.cells.size(); ++c) spec.cells[c].delay = std::min(delays[c] + lowered[c], b.level);
    const bcifs::VolumeRules rules = volume_rules(spec);
    const double cells = bcifs::volume_cells(rules, b.level);
    if (cells > bcifs::kMaxVolumeCells)
      throw ResourceLimit(where() + ": " + std::to_string(spec.cells.size()) + " tetrahedra at level " +
                          std::to_string(b.level) + " make " + message_number(cells) + " cells, more than " +
                          message_number(bcifs::kMaxVolumeCells) + "; use larger cell_mm or a lower level");
    // The lacunas the last level makes (tetrahedra still all delayed make none); with equal_lacunas every one is
    // brought down to the smallest of those the tetrahedra graded alike make (a cell's own lacuna touches no
    // face it shares, so each takes its own scale).
    bcifs::VolumeGeometryOptions options = b.options;
    if (b.equal_lacunas) {
      const bcifs::LastLacunas plain = bcifs::last_lacuna_sizes(rules, spec, b.level, options);
      std::vector<double> target(size_t(b.grade_levels) + 1, HUGE_VAL);
      for (size_t c = 0; c < spec.cells.size(); ++c)
        if (plain.smallest_mm[c] > 0)
          target[size_t(lowered[c])] = std::min(target[size_t(lowered[c])], plain.smallest_mm[c]);
      options.last_lacuna_mm.assign(spec.cells.size(), 0.0);
      for (size_t c = 0; c < spec.cells.size(); ++c)
        if (std::isfinite(target[size_t(lowered[c])])) options.last_lacuna_mm[c] = target[size_t(lowered[c])];
    }
    const bcifs::LastLacunas lacunas = bcifs::last_lacuna_sizes(rules, spec, b.level, options);
    BcifsVolumeReport report;
    add_cells(rules, spec, b.level, options, report);
    report.tetrahedra = spec.cells.size();
    report.min_cell_mm = *std::min_element(sizes.begin(), sizes.end());
    report.max_cell_mm = *std::max_element(sizes.begin(), sizes.end());
    for (const bcifs::CellSpec& c : spec.cells) report.max_delay = std::max(report.max_delay, c.delay);
    report.min_lacuna_mm = HUGE_VAL;
    for (size_t c = 0; c < spec.cells.size(); ++c)
      if (lacunas.largest_mm[c] > 0) {
        report.min_lacuna_mm = std::min(report.min_lacuna_mm, lacunas.smallest_mm[c]);
        report.max_lacuna_mm = std::max(report.max_lacuna_mm, lacunas.largest_mm[c]);
      }
    if (!(report.max_lacuna_mm > 0)) report.min_lacuna_mm = 0;
    report.min_lacuna_scale = lacunas.min_scale;
    report.max_lacuna_scale = lacunas.max_scale;
    report.min_level = b.level - *std::max_element(lowered.begin(), lowered.end());
    report.max_level = b.level - *std::min_element(lowered.begin(), lowered.end());
    out_.report = report;
  }

  const RecipeInput& in_;
  const BuildContext& context_;
  const Recipe& recipe_;
  const VolumeOptions vopt_;
  BuiltInput out_;
};

}  // namespace

const BuiltInput& BuiltInputs::at(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return inputs[i];
  throw InternalError("no input is named \"" + name + "\"");
}

BuiltInput build_input(const RecipeInput& input, const BuildContext& context) { return Builder(input, context).build(); }

BuiltInputs build_inputs(const Recipe& recipe, uint64_t max_memory_bytes) {
  BuiltInputs built;
  for (const RecipeInput& in : recipe.inputs) built.names.push_back(in.name);
  built.inputs.resize(recipe.inputs.size());
  const BuildContext context{&recipe, &built, max_memory_bytes ? max_memory_bytes : available_memory_bytes() / 2};
  ProgressSink* sink = current_progress_sink();
  for (size_t i = 0; i < recipe.inputs.size(); ++i) {
    if (built_after_others(recipe.inputs[i].spec)) continue;
    throw_if_cancelled(sink);
    built.inputs[i] = build_input(recipe.inputs[i], context);
  }
  // Inputs built from other inputs (lattices fitted to a hull, grades by depth in it), in order.
  for (size_t i = 0; i < recipe.inputs.size(); ++i) {
    const RecipeInput& in = recipe.inputs[i];
    if (!built_after_others(in.spec)) continue;
    for (const std::string& dep : dependencies(in.spec))
      for (const RecipeInput& other : recipe.inputs)
        if (other.name == dep && built_after_others(other.spec))
          throw InvalidInput(recipe.file + ": " + in.json_path + ": \"" + dep + "\" is itself built from another input");
    throw_if_cancelled(sink);
    built.inputs[i] = build_input(in, context);
  }
  for (size_t i = 0; i < recipe.inputs.size(); ++i) {
    try {
      validate(built.inputs[i].geometry);
    } catch (const InvalidInput& e) {
      throw InvalidInput(recipe.file + ": " + recipe.inputs[i].json_path + ": " + e.what());
    }
  }
  return built;
}

bcifs::Plate build_plate(const BcifsPlateInput& input, const std::string& file, const std::string& path) {
  bcifs::Plate plate;
  plate.options = input.plate;
  const bcifs::PlateOptions& o = plate.options;
  try {
    plate.rules = bcifs::build_rules(o.assembly.faces);
  } catch (const InvalidInput& e) {
    throw InvalidInput(file + ": " + path + ": " + e.what());
  } catch (const ResourceLimit& e) {
    throw ResourceLimit(file + ": " + path + ": " + e.what());
  }
  // Leaves grow by the spectral radius per level; refuse before building millions.
  const double leaves = bcifs::plate_leaves(plate);
  if (leaves > bcifs::kMaxPlateLeaves)
    throw ResourceLimit(file + ": " + path + ".level: level " + std::to_string(o.level) + " has " +
                        std::to_string(int64_t(leaves)) + " sub-faces, more than 2 000 000; use a lower level");
  // The shared edges must have the same end points (reversed) on both sides.
  try {
    bcifs::realize_assembly(plate.rules, o.assembly, o.controls, 0, o.options, o.bends);
  } catch (const InvalidInput& e) {
    throw InvalidInput(file + ": " + path + "." + (input.faces_listed ? "faces" : "face") + ": " + e.what());
  }
  return plate;
}

}  // namespace lacuna
