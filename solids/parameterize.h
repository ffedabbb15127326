// Flattening a disk-like triangle patch onto the square (-1, 1)^2, and the patch as a surface map on
// which space-filling curves are drawn (src/curves/curves.h). CGAL's Surface_mesh_parameterization does
// the flattening: an arc-length square border and mean-value coordinates inside (Floater), whose weights
// are positive, so by Tutte's theorem no triangle folds over; only triangles with all three corners on one
// side of the square can come out flat.
#pragma once

#include <string>
#include <vector>

#include "curves/curves.h"
#include "geometry.h"

namespace lacuna {

// The square coordinates (X, Y) in [-1, 1]^2 of each vertex of `patch` (NaN for vertices no triangle
// uses). The patch must be disk-like: triangles with three distinct corners and positive area, finite
// positions, one connected component, manifold at every edge and vertex, consistently oriented, exactly
// one boundary loop of at least 4 edges, Euler characteristic 1. The boundary goes onto the square's
// border by arc length, its corners onto 4 boundary vertices: a start vertex and the 3 vertices closest
// to a quarter, half and three quarters of the boundary's length from it, the start chosen so that the
// fewest triangles have all three corners on one side of the square (they would flatten to a segment),
// then the sharpest corners (largest sum of the 4 turning angles), then the lowest vertex index (on
// boundaries of more than 256 vertices, among the 256 where the boundary turns most). The
// start goes to (-1, -1) and the others follow counter-clockwise, so the map keeps orientation: the
// patch's counter-clockwise triangles stay counter-clockwise in the square. Deterministic.
// Throws InvalidInput saying what is wrong with a patch that is not disk-like, or when a flattened
// triangle comes out flat or flipped.
std::vector<Vec2d> flatten_patch(const TriMesh& patch);

// The patch as a map from the square: point(X, Y) is the point of the patch whose flattened position
// (flatten_patch) is (X, Y), interpolated linearly in the flattened triangle that contains it (found
// through a grid of buckets; a point on an edge or vertex gets the same point from either side; (X, Y)
// outside the square is clamped onto it; NaN gives NaN). normal(X, Y) is the unit normal of that
// triangle, on the side from which the patch's triangles are counter-clockwise. Copies share the data.
// Throws as flatten_patch().
curves::SurfaceMap mesh_patch_map(const TriMesh& patch, const std::string& name = "mesh patch");

}  // namespace lacuna
