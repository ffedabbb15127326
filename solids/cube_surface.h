// The marching-tetrahedra surface of one grid cube (the Freudenthal split into six tetrahedra),
// and a coarser triangulation of the same patches that leaves out the crossings on the cube's
// body diagonal and, where the face allows it, on its face diagonals. Pure geometry (no OpenVDB):
// corner values and crossing positions in, triangles named by the cube's edges out.
//
// Why a merged cube keeps the surface valid. Every crossing of a cube lies in the closed cube,
// so every triangle of the cube does (it is convex). Two cubes meet in a face, an edge or a grid
// point; a triangle meets the plane of a face of its cube in one of its own faces (a vertex, an
// edge, or all of it). A merged triangle never lies in a face (no three of its corners share a
// face), and each of its edges whose ends share a face is one of that face's segments: the pieces
// of the face's own marching-triangles contour, with the diagonal crossing or without it as the
// face (not the cube) decides. Both cubes of a face see the same segments, so triangles of
// different cubes meet only in shared vertices and edges; pairs inside one cube are tested with
// exact predicates. Each patch is a disk replaced by a disk on the same boundary, so the surface
// keeps its topology; a cube whose patches are not all disks keeps its marching-tetrahedra pieces.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "geometry.h"

namespace lacuna::cube_surface {

// Corner c of a cube is the offset (c & 1, (c >> 1) & 1, (c >> 2) & 1). A crossing is named by
// its edge, slot = lo * 8 + dir: lo its lower corner and dir the axes it runs along (lo & dir == 0).
constexpr int kSlots = 64;
inline int slot_of(int ci, int cj) { return (ci & cj) * 8 + (ci ^ cj); }

// Faces are numbered 2 * axis + side (side 1: the face at the cube's upper coordinate). The faces
// containing the edge of a slot, as bits.
uint8_t faces_of_slot(int slot);
// Whether the slot is a face diagonal (two axes), and then its face.
bool is_face_diagonal(int slot);
int face_of_diagonal(int slot);

// Even permutations of (0, 1, 2, 3) that start with a given corner, and with a given pair.
constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 7, 5}, {0, 2, 7, 3}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 7, 6}};
constexpr int kEvenFrom[4][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}, {2, 3, 0, 1}, {3, 2, 1, 0}};
inline void even_from_pair(int a, int b, int out[4]) {
  static constexpr int kPairs[6][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 2, 0}, {2, 3, 0, 1}};
  for (const auto& p : kPairs)
    if (p[0] == a && p[1] == b) {
      for (int k = 0; k < 4; ++k) out[k] = p[k];
      return;
    }
}

// Writes the triangles of the six tetrahedra of one cube (corner values f, inside-corner bits
// `inside`) to out and returns the new end; vertex(ci, cj) names the crossing on the edge between
// cube corners ci and cj. Each tetrahedron is a monotone path 0 -> e_a -> e_a + e_b -> 7, listed in
// positive orientation. A triangle faces away from its tetrahedron's inside corners; a quad is
// split along its shorter diagonal, measured on the cube-local crossing positions.
template <class VertexOf, class Triangle>
Triangle* cube_triangles(const float f[8], int inside, double eps, VertexOf&& vertex, Triangle* out) {
  for (const auto& tet : kTets) {
    int in_count = 0;
    for (int k = 0; k < 4; ++k) in_count += (inside >> tet[k]) & 1;
    if (in_count == 0 || in_count == 4) continue;
    if (in_count == 1 || in_count == 3) {
      const bool want_inside = in_count == 1;
      int lone = 0;
      for (int k = 0; k < 4; ++k)
        if ((((inside >> tet[k]) & 1) != 0) == want_inside) lone = k;
      const int* p = kEvenFrom[lone];
      const auto a = vertex(tet[p[0]], tet[p[1]]), b = vertex(tet[p[0]], tet[p[2]]), c = vertex(tet[p[0]], tet[p[3]]);
      // (a, b, c) faces away from the lone corner; outward is away from an inside corner.
      if (want_inside) *out++ = {a, b, c};
      else *out++ = {a, c, b};
      continue;
    }
    int ins[2], k2 = 0;
    for (int k = 0; k < 4; ++k)
      if ((inside >> tet[k]) & 1) ins[k2++] = k;
    int p[4] = {0, 1, 2, 3};
    even_from_pair(ins[0], ins[1], p);
    // Quad (ac, ad, bd, bc) is oriented from {a, b} (inside) towards {c, d}.
    const decltype(vertex(0, 1)) q[4] = {vertex(tet[p[0]], tet[p[2]]), vertex(tet[p[0]], tet[p[3]]),
                                         vertex(tet[p[1]], tet[p[3]]), vertex(tet[p[1]], tet[p[2]])};
    auto local = [&](int ci, int cj) {
      const int lo = ci & cj, dir = ci ^ cj;
      const float f0 = f[lo], f1 = f[lo | dir];
      const double t = std::min(std::max(double(f0) / (double(f0) - double(f1)), eps), 1.0 - eps);
      return Vec3d{(lo & 1) + t * (dir & 1), ((lo >> 1) & 1) + t * ((dir >> 1) & 1), ((lo >> 2) & 1) + t * ((dir >> 2) & 1)};
    };
    const Vec3d l0 = local(tet[p[0]], tet[p[2]]), l1 = local(tet[p[0]], tet[p[3]]), l2 = local(tet[p[1]], tet[p[3]]),
                l3 = local(tet[p[1]], tet[p[2]]);
    const Vec3d d02 = l2 - l0, d13 = l3 - l1;
    if (dot(d02, d02) <= dot(d13, d13)) {
      *out++ = {q[0], q[1], q[2]};
      *out++ = {q[0], q[2], q[3]};
    } else {
      *out++ = {q[0], q[1], q[3]};
      *out++ = {q[1], q[2], q[3]};
    }
  }
  return out;
}

// Triangles the six tetrahedra of a cube produce, from its inside-corner bits.
int triangles_in_cube(int inside);

// Whether some patch of the cube's marching-tetrahedra surface is not a disk (e.g. the tube
// around the body diagonal when only corners 0 and 7 are inside): such a cube keeps its pieces.
bool keeps_pieces(int inside);

// Whether the face's diagonal is crossed (its ends on different sides) for these inside bits.
bool diagonal_crossed(int inside, int face);

struct MergeInput {
  int inside = 0;                 // bit c: corner c is inside
  const float* values = nullptr;  // the 8 corner values
  double eps = 0.01;              // the extraction's crossing clamp (as a fraction of an edge)
  const Vec3d* positions = nullptr;  // positions[slot] for every crossing of the cube (float32 values)
  Vec3d box_lo, box_hi;              // the cube's corners (float32 values, as the positions)
  uint8_t kept_faces = 0;            // faces whose diagonal crossing stays (bit per face)
  double max_deviation_mm = 0;       // how far the merged patches may stray from the pieces
  // For tests: decide every candidate by the sampled tests (no flat patch's proof), and count
  // the patches whose triangulation was taken on the proof.
  bool sampled_tests_only = false;
  uint64_t* proven_candidates = nullptr;
};

// What a merge costs in volume: six times the volume the merged patches enclose less than the
// pieces did, shared out evenly among each patch's boundary crossings (the cube's face
// triangles a-d-b, where a diagonal crossing d is left out, counted so that the two cubes of a
// face cancel: the shares of all cubes sum to the whole surface's loss).
struct VolumeShares {
  uint8_t slots[24];
  double volume6[24];
  int count = 0;
};

// The cube's merged triangles (slots, counter-clockwise seen from outside), appended to out:
// every patch's boundary triangulated without the crossings left out, as shaped as the tests
// allow. False (out unchanged) when some patch has no triangulation that passes every test
// (exact: no degenerate triangle, no pair of the cube's triangles meeting beyond what they
// share, the face rules above; sampled: the left-out crossings and the new triangles within
// the deviation of the pieces, no triangle facing away from the pieces near it). On a flat
// patch an exact argument (see the source) shows that the sampled tests pass without running
// them: the same triangles either way.
bool merged_triangles(const MergeInput& in, std::vector<std::array<uint8_t, 3>>& out, VolumeShares* lost = nullptr);

}  // namespace lacuna::cube_surface
