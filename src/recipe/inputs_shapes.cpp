// Inputs given directly: spheres, capsules, tubes, analytic shapes, planar regions and meshes.
#include <cmath>
#include <string>

#include "recipe/input_parsers.h"

namespace lacuna {
namespace {

TriMesh inline_mesh(const JsonObject& o) {
  TriMesh mesh;
  mesh.positions_mm = o.vec3_list("positions_mm");
  const nlohmann::json& tris = o.required("triangles");
  if (!tris.is_array()) o.fail("triangles", "expected a list of [i, j, k] vertex indices");
  for (size_t t = 0; t < tris.size(); ++t) {
    const nlohmann::json& tri = tris[t];
    std::string where = "triangles[" + std::to_string(t) + "]";
    if (!tri.is_array() || tri.size() != 3) o.fail(where, "expected [i, j, k]");
    std::array<uint32_t, 3> idx{};
    for (int k = 0; k < 3; ++k) {
      if (!tri[k].is_number_integer() || tri[k].get<int64_t>() < 0 ||
          tri[k].get<uint64_t>() >= mesh.positions_mm.size())
        o.fail(where, "expected vertex indices from 0 to " + std::to_string(mesh.positions_mm.size()) + " - 1");
      idx[k] = tri[k].get<uint32_t>();
    }
    mesh.triangles.push_back(idx);
  }
  if (mesh.triangles.empty()) o.fail("triangles", "expected at least one triangle");
  return mesh;
}

MeshRepair parse_repair(const JsonObject& o) {
  MeshRepair repair;
  if (!o.has("repair")) return repair;
  JsonObject r = o.object("repair");
  r.allow_only({"weld_mm", "reorient", "close_gaps_mm", "allow_overlaps"});
  repair.weld_mm = r.positive_length_or("weld_mm", 0.0);
  repair.reorient = r.boolean_or("reorient", false);
  repair.close_gaps_mm = r.positive_length_or("close_gaps_mm", 0.0);
  repair.allow_overlaps = r.boolean_or("allow_overlaps", false);
  return repair;
}

// A file to import, or vertices and triangles inline; `thickness_mm` is read for surfaces, between the
// placement and the mesh itself (the order its messages come in).
MeshSource parse_mesh_source(const JsonObject& o, double* thickness_mm) {
  MeshSource source;
  bool has_file = o.has("file"), has_inline = o.has("positions_mm") || o.has("triangles");
  if (has_file == has_inline) o.fail("", "give either \"file\" or \"positions_mm\" and \"triangles\"");
  source.scale = o.has("scale") ? o.positive_length("scale") : 1.0;
  source.translate_mm = o.vec3_or("translate_mm", Vec3d{});
  if (thickness_mm) *thickness_mm = o.positive_length("thickness_mm");
  if (has_file) {
    source.file = o.string("file");
    if (source.file.empty()) o.fail("file", "expected a file name");
    return source;
  }
  source.inline_mesh = inline_mesh(o);
  return source;
}

}  // namespace

SphereInput parse_sphere_input(const JsonObject& o) {
  SphereInput in;
  in.center_mm = o.vec3_or("center_mm", Vec3d{});
  in.radius_mm = o.positive_length("radius_mm");
  return in;
}

SpheresInput parse_spheres_input(const JsonObject& o) {
  SpheresInput s;
  s.centers_mm = o.vec3_list("centers_mm");
  if (s.centers_mm.empty()) o.fail("centers_mm", "expected at least one centre");
  if (o.has("radius_mm") == o.has("radii_mm")) o.fail("", "give either \"radius_mm\" or \"radii_mm\"");
  if (o.has("radius_mm")) s.radii_mm = {o.positive_length("radius_mm")};
  else s.radii_mm = o.positive_length_list("radii_mm");
  if (o.has("radii_mm") && s.radii_mm.size() != s.centers_mm.size())
    o.fail("radii_mm", "expected one radius per centre (" + std::to_string(s.centers_mm.size()) + "), got " +
                           std::to_string(s.radii_mm.size()) + "; give \"radius_mm\" for one radius for all");
  return s;
}

CapsuleInput parse_capsule_input(const JsonObject& o) {
  CapsuleInput c;
  c.radius_mm = o.positive_length("radius_mm");
  c.radius_b_mm = o.positive_length_or("radius_b_mm", c.radius_mm);
  c.a_mm = o.vec3("a_mm");
  c.b_mm = o.vec3("b_mm");
  return c;
}

TubesInput parse_tubes_input(const JsonObject& o) {
  TubesInput in;
  const nlohmann::json& list = o.required("polylines");
  if (!list.is_array() || list.empty()) o.fail("polylines", "expected a non-empty list of polylines");
  for (size_t i = 0; i < list.size(); ++i) {
    JsonObject p(list[i], o.file(), o.path_of("polylines[" + std::to_string(i) + "]"));
    p.allow_only({"points_mm", "radius_mm", "radii_mm"});
    Tube tube;
    tube.points_mm = p.vec3_list("points_mm");
    if (tube.points_mm.empty()) p.fail("points_mm", "expected at least one point");
    if (p.has("radius_mm") == p.has("radii_mm")) p.fail("", "give either \"radius_mm\" or \"radii_mm\"");
    if (p.has("radius_mm")) tube.radii_mm = {p.positive_length("radius_mm")};
    else tube.radii_mm = p.positive_length_list("radii_mm");
    if (p.has("radii_mm") && tube.radii_mm.size() != tube.points_mm.size())
      p.fail("radii_mm", "expected one radius per point (" + std::to_string(tube.points_mm.size()) + "), got " +
                             std::to_string(tube.radii_mm.size()) + "; give \"radius_mm\" for one radius for all");
    in.polylines.push_back(std::move(tube));
  }
  return in;
}

BoxInput parse_box_input(const JsonObject& o) {
  BoxInput b;
  if (o.has("size_mm")) {
    if (o.has("min_mm") || o.has("max_mm")) o.fail("", "give either \"center_mm\" and \"size_mm\" or \"min_mm\" and \"max_mm\"");
    Vec3d size = o.vec3("size_mm");
    if (!(size.x > 0 && size.y > 0 && size.z > 0)) o.fail("size_mm", "expected three positive lengths in mm");
    b.center_mm = o.vec3_or("center_mm", Vec3d{});
    b.half_size_mm = size * 0.5;
  } else {
    if (o.has("center_mm")) o.fail("center_mm", "give \"size_mm\" with \"center_mm\"");
    Vec3d lo = o.vec3("min_mm"), hi = o.vec3("max_mm");
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) o.fail("max_mm", "expected max_mm > min_mm on every axis");
    b.center_mm = (lo + hi) * 0.5;
    b.half_size_mm = (hi - lo) * 0.5;
  }
  return b;
}

CylinderInput parse_cylinder_input(const JsonObject& o) {
  CylinderInput c;
  c.center_mm = o.vec3_or("center_mm", Vec3d{});
  c.axis = o.direction_or("axis", Vec3d{0, 0, 1});
  c.radius_mm = o.positive_length("radius_mm");
  c.height_mm = o.positive_length("height_mm");
  return c;
}

TorusInput parse_torus_input(const JsonObject& o) {
  TorusInput t;
  t.center_mm = o.vec3_or("center_mm", Vec3d{});
  t.axis = o.direction_or("axis", Vec3d{0, 0, 1});
  t.major_radius_mm = o.positive_length("major_radius_mm");
  t.minor_radius_mm = o.positive_length("minor_radius_mm");
  if (t.minor_radius_mm >= t.major_radius_mm) o.fail("minor_radius_mm", "expected less than major_radius_mm");
  return t;
}

RegionInput parse_region_input(const JsonObject& o) {
  RegionInput in;
  Region2& r = in.region;
  const nlohmann::json& loops = o.required("loops_mm");
  if (!loops.is_array() || loops.empty()) o.fail("loops_mm", "expected a list of loops of [x, y] points");
  for (size_t i = 0; i < loops.size(); ++i) {
    std::string key = "loops_mm[" + std::to_string(i) + "]";
    r.loops_mm.push_back(o.vec2_list(loops[i], key));
    if (r.loops_mm.back().size() < 3) o.fail(key, "a loop needs at least 3 points");
  }
  r.height_mm = o.positive_length("height_mm");
  r.origin_mm = o.vec3_or("origin_mm", Vec3d{});
  r.axis_u = o.direction_or("axis_u", Vec3d{1, 0, 0});
  r.axis_v = o.direction_or("axis_v", Vec3d{0, 1, 0});
  if (std::fabs(dot(r.axis_u, r.axis_v)) > 1e-9) o.fail("axis_v", "expected a direction orthogonal to axis_u");
  return in;
}

MeshInput parse_mesh_input(const JsonObject& o) {
  MeshInput in;
  in.repair = parse_repair(o);
  in.source = parse_mesh_source(o, nullptr);
  return in;
}

SurfaceInput parse_surface_input(const JsonObject& o) {
  SurfaceInput in;
  in.source = parse_mesh_source(o, &in.thickness_mm);
  return in;
}

}  // namespace lacuna
