// Each recipe input type's JSON object read into its options (recipe/inputs.h): values checked and
// named in messages, nothing built. The keys an object may have are checked by the caller.
#pragma once

#include "recipe/inputs.h"
#include "recipe/json_fields.h"

namespace lacuna {

SphereInput parse_sphere_input(const JsonObject& o);
SpheresInput parse_spheres_input(const JsonObject& o);
CapsuleInput parse_capsule_input(const JsonObject& o);
TubesInput parse_tubes_input(const JsonObject& o);
BoxInput parse_box_input(const JsonObject& o);
CylinderInput parse_cylinder_input(const JsonObject& o);
TorusInput parse_torus_input(const JsonObject& o);
RegionInput parse_region_input(const JsonObject& o);
MeshInput parse_mesh_input(const JsonObject& o);
SurfaceInput parse_surface_input(const JsonObject& o);
LatticeInput parse_lattice_input(const JsonObject& o);
CifsInput parse_cifs_input(const JsonObject& o);
// A cifs shell on its own support tree: the keys of a cifs shell with those of its "support" beside them.
CifsInput parse_cifs_support_input(const JsonObject& o);
CurveInput parse_curve_input(const JsonObject& o);
FillMotifsInput parse_fill_motifs_input(const JsonObject& o);
FillSpheresInput parse_fill_spheres_input(const JsonObject& o);
VoronoiSpheresInput parse_voronoi_spheres_input(const JsonObject& o);
VoronoiTilesInput parse_voronoi_tiles_input(const JsonObject& o);
VoronoiFoamInput parse_voronoi_foam_input(const JsonObject& o);
BcifsCellInput parse_bcifs_cell_input(const JsonObject& o);
BcifsVolumeInput parse_bcifs_volume_input(const JsonObject& o);
BcifsInfillInput parse_bcifs_infill_input(const JsonObject& o);

// A `bcifs_plate` object: "face" {boundary, params, algorithm, delay, control_mm, bends_mm} or "faces" [...]
// with "shared" [{face_a, edge_a, face_b, edge_b}], "level", "thickness_mm", "radius_mm" (a face without
// control_mm is the regular polygon of that circumradius), "gap_fraction", "lacuna_scale", "notch_depth",
// "origin_mm". Also read by `lacuna bcifs measure`, which takes the objects of a recipe as they are.
BcifsPlateInput parse_bcifs_plate_input(const JsonObject& o);

// A tensor-product B-spline patch {degree_u, degree_v, count_u, count_v, control_points_mm (u fastest)}: a
// curve input's "patch", and the file `lacuna curve points|fill-rate --surface bspline --patch` reads.
curves::BSplinePatch parse_bspline_patch(const JsonObject& p);

// A grade's field: "field" ramp {axis, from_mm, to_mm}, points {points_mm, falloff_mm} or depth {depth_mm}. A depth
// field is refused with `no_depth` as the message unless that is empty (the input has a hull to measure it in).
GradeField parse_grade_field(const JsonObject& g, const std::string& no_depth);

}  // namespace lacuna
