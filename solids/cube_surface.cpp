#include "solids/cube_surface.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "solids/disjoint_sets.h"
#include "solids/exact.h"
#include "solids/mesh_distance.h"

namespace lacuna::cube_surface {
namespace {

using Tri8 = std::array<uint8_t, 3>;

constexpr int kMaxLoop = 8;      // longest boundary a merged patch may have (132 triangulations)
constexpr int kMaxPatches = 4;   // patches of one cube's pieces (at most four corners cut off)
constexpr int kMaxSlotsInLoop = 16;

struct Patch {
  uint8_t loop[kMaxSlotsInLoop];  // the boundary's crossings in order (the pieces' orientation)
  uint8_t loop_length = 0;
  uint8_t interior[4];            // crossings inside the cube (the body diagonal's at most)
  uint8_t interior_count = 0;
};

// The topology of a cube's pieces, a function of the inside bits alone.
struct Case {
  bool keeps_pieces = false;  // some patch is not a disk
  uint8_t patch_count = 0;
  Patch patches[kMaxPatches];
  uint8_t patch_of_slot[kSlots];
};

int popcount3(int d) { return (d & 1) + ((d >> 1) & 1) + ((d >> 2) & 1); }

std::array<Case, 256> make_cases() {
  std::array<Case, 256> cases{};
  for (int inside = 1; inside < 255; ++inside) {
    Case& c = cases[size_t(inside)];
    std::fill(std::begin(c.patch_of_slot), std::end(c.patch_of_slot), uint8_t(0xff));
    float f[8];
    for (int k = 0; k < 8; ++k) f[k] = ((inside >> k) & 1) ? -1.0f : 1.0f;
    Tri8 tris[12];
    const Tri8* end = cube_triangles(f, inside, 0.01, [](int ci, int cj) { return uint8_t(slot_of(ci, cj)); }, tris);
    const int nt = int(end - tris);
    std::map<std::pair<int, int>, int> uses;  // undirected edge -> triangles using it
    for (int t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        const int a = tris[t][size_t(k)], b = tris[t][size_t((k + 1) % 3)];
        ++uses[{std::min(a, b), std::max(a, b)}];
      }
    DisjointSets sets{size_t(nt)};
    for (int t = 0; t < nt; ++t)
      for (int u = t + 1; u < nt; ++u)
        for (int k = 0; k < 3; ++k)
          for (int j = 0; j < 3; ++j) {
            const int a = tris[t][size_t(k)], b = tris[t][size_t((k + 1) % 3)];
            const int x = tris[u][size_t(j)], y = tris[u][size_t((j + 1) % 3)];
            if (a == y && b == x && uses[{std::min(a, b), std::max(a, b)}] == 2) sets.join(uint32_t(t), uint32_t(u));
          }
    std::vector<int> root_patch(size_t(nt), -1);
    for (int t = 0; t < nt; ++t) {
      const uint32_t r = sets.find(uint32_t(t));
      if (root_patch[r] < 0) root_patch[r] = c.patch_count++;
    }
    for (int p = 0; p < c.patch_count; ++p) {
      Patch& patch = c.patches[p];
      std::vector<int> vertices;
      std::map<int, int> next;  // boundary half-edges a -> b
      int faces = 0, edges2 = 0;
      for (int t = 0; t < nt; ++t) {
        if (root_patch[sets.find(uint32_t(t))] != p) continue;
        ++faces;
        for (int k = 0; k < 3; ++k) {
          const int a = tris[t][size_t(k)], b = tris[t][size_t((k + 1) % 3)];
          vertices.push_back(a);
          const int n = uses[{std::min(a, b), std::max(a, b)}];
          edges2 += n == 1 ? 2 : 1;  // an interior edge is seen from both of its triangles
          if (n == 1) next[a] = b;
        }
      }
      std::sort(vertices.begin(), vertices.end());
      vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
      for (int v : vertices) c.patch_of_slot[v] = uint8_t(p);
      const int euler = int(vertices.size()) - edges2 / 2 + faces;
      // The boundary: one loop through every boundary vertex, or the patch is not a disk.
      int loops = 0;
      std::map<int, bool> seen;
      for (const auto& [start, ignored] : next) {
        (void)ignored;
        if (seen[start]) continue;
        ++loops;
        for (int v = start; !seen[v]; v = next.at(v)) {
          seen[v] = true;
          if (loops == 1 && patch.loop_length < kMaxSlotsInLoop) patch.loop[patch.loop_length++] = uint8_t(v);
        }
      }
      for (int v : vertices)
        if (!next.count(v) && patch.interior_count < 4) patch.interior[patch.interior_count++] = uint8_t(v);
      if (loops != 1 || euler != 1 || int(next.size()) > kMaxSlotsInLoop) c.keeps_pieces = true;
    }
    if (c.patch_count > kMaxPatches) c.keeps_pieces = true;
  }
  return cases;
}

const Case& case_of(int inside) {
  static const std::array<Case, 256> cases = make_cases();
  return cases[size_t(inside)];
}

// Triangulations of a convex k-gon (0 .. k-1), each as its k - 2 triangles (i < j < l, which is
// the polygon's own orientation).
struct Triangulations {
  std::vector<std::vector<std::array<uint8_t, 3>>> of_size[kMaxLoop + 1];
};

void triangulate_range(int i, int j, std::vector<std::vector<std::array<uint8_t, 3>>>& out) {
  // All triangulations of the polygon i, i+1, ..., j (closed by the chord j-i).
  out.clear();
  if (j - i < 2) {
    out.push_back({});
    return;
  }
  for (int m = i + 1; m < j; ++m) {
    std::vector<std::vector<std::array<uint8_t, 3>>> left, right;
    triangulate_range(i, m, left);
    triangulate_range(m, j, right);
    for (const auto& l : left)
      for (const auto& r : right) {
        std::vector<std::array<uint8_t, 3>> t = l;
        t.insert(t.end(), r.begin(), r.end());
        t.push_back({uint8_t(i), uint8_t(m), uint8_t(j)});
        out.push_back(std::move(t));
      }
  }
}

const Triangulations& triangulations() {
  static const Triangulations all = [] {
    Triangulations t;
    for (int k = 3; k <= kMaxLoop; ++k) triangulate_range(0, k - 1, t.of_size[k]);
    return t;
  }();
  return all;
}

double squared(const Vec3d& v) { return dot(v, v); }

// A triangle of crossings made ready for "is q within d of it": its box grown by d and its
// normal. Plain data, so arrays of these cost nothing to declare.
struct NearTriangle {
  const Vec3d* pos;
  uint8_t a, b, c;
  double lo[3], hi[3];
  double normal[3];  // cross(b - a, c - a)
  double length;     // of the normal
  void set(const Vec3d* positions, const Tri8& t, double d) {
    pos = positions;
    a = t[0], b = t[1], c = t[2];
    const Vec3d &pa = pos[a], &pb = pos[b], &pc = pos[c];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min({pa[k], pb[k], pc[k]}) - d;
      hi[k] = std::max({pa[k], pb[k], pc[k]}) + d;
    }
    const Vec3d n = cross(pb - pa, pc - pa);
    normal[0] = n.x, normal[1] = n.y, normal[2] = n.z;
    length = norm(n);
  }
  Vec3d normal_vector() const { return {normal[0], normal[1], normal[2]}; }
  // d2: squared_limit(d), so the squared distance decides as the distance would.
  bool near(const Vec3d& q, double d, double d2) const {
    if (q.x < lo[0] || q.x > hi[0] || q.y < lo[1] || q.y > hi[1] || q.z < lo[2] || q.z > hi[2]) return false;
    const Vec3d& pa = pos[a];
    if (std::fabs(normal[0] * (q.x - pa.x) + normal[1] * (q.y - pa.y) + normal[2] * (q.z - pa.z)) > d * length)
      return false;  // even its plane is farther
    return point_triangle_distance2(q, pa, pos[b], pos[c]) <= d2;
  }
};

}  // namespace

uint8_t faces_of_slot(int slot) {
  const int lo = slot >> 3, dir = slot & 7;
  uint8_t faces = 0;
  for (int k = 0; k < 3; ++k)
    if (!((dir >> k) & 1)) faces |= uint8_t(1u << (2 * k + ((lo >> k) & 1)));
  return faces;
}

bool is_face_diagonal(int slot) { return popcount3(slot & 7) == 2; }

int face_of_diagonal(int slot) {
  const int lo = slot >> 3, dir = slot & 7;
  for (int k = 0; k < 3; ++k)
    if (!((dir >> k) & 1)) return 2 * k + ((lo >> k) & 1);
  return -1;
}

int triangles_in_cube(int inside) {
  int n = 0;
  for (const auto& tet : kTets) {
    int in_count = 0;
    for (int k = 0; k < 4; ++k) in_count += (inside >> tet[k]) & 1;
    n += in_count == 2 ? 2 : (in_count == 1 || in_count == 3 ? 1 : 0);
  }
  return n;
}

bool keeps_pieces(int inside) { return case_of(inside).keeps_pieces; }

bool diagonal_crossed(int inside, int face) {
  const int axis = face / 2, side = face % 2;
  const int a = (axis + 1) % 3, b = (axis + 2) % 3;
  const int lo = side << axis, hi = lo | (1 << a) | (1 << b);
  return ((inside >> lo) & 1) != ((inside >> hi) & 1);
}

bool merged_triangles(const MergeInput& in, std::vector<std::array<uint8_t, 3>>& out, VolumeShares* lost) {
  const Case& c = case_of(in.inside);
  if (c.keeps_pieces) return false;
  const Vec3d* pos = in.positions;
  const double dev = in.max_deviation_mm;
  // Its squared limit, worked out once per thread and deviation (every cube of a surface shares it).
  static thread_local double limit_of = -1, limit2 = 0;
  if (dev != limit_of) limit2 = squared_limit(dev), limit_of = dev;
  const double dev2 = limit2;

  // The faces each crossing lies on, from its coordinates: they must be the faces of its edge,
  // or float32 rounding moved it onto a plane and the face rules would not hold.
  auto faces_at = [&](int slot) {
    uint8_t faces = 0;
    for (int k = 0; k < 3; ++k) {
      if (pos[slot][k] == in.box_lo[k]) faces |= uint8_t(1u << (2 * k));
      if (pos[slot][k] == in.box_hi[k]) faces |= uint8_t(1u << (2 * k + 1));
    }
    return faces;
  };

  // The pieces, by patch.
  Tri8 pieces[12];
  const int piece_count =
      int(cube_triangles(in.values, in.inside, in.eps, [](int ci, int cj) { return uint8_t(slot_of(ci, cj)); }, pieces) -
          pieces);

  const size_t first_out = out.size();
  Tri8 result[24];
  uint8_t result_new[24];
  int result_count = 0;
  auto fail = [&] {
    out.resize(first_out);
    return false;
  };
  if (lost) lost->count = 0;
  // Six times the volume of the cone from the cube's corner over a triangle (any fixed point
  // gives the same sums over closed surfaces; a near one keeps the digits).
  auto cone6 = [&](int a, int b, int d) {
    return dot(pos[a] - in.box_lo, cross(pos[b] - in.box_lo, pos[d] - in.box_lo));
  };

  for (int p = 0; p < c.patch_count; ++p) {
    const Patch& patch = c.patches[p];
    // The boundary without the diagonal crossings of faces that let them go.
    uint8_t loop[kMaxSlotsInLoop], faces[kMaxSlotsInLoop], at[kMaxSlotsInLoop];
    uint8_t removed[kMaxSlotsInLoop + 4];
    int k = 0, removed_count = 0;
    // The farthest a left-out crossing lies from the segment between its neighbours, squared (its
    // root is taken once: the root is monotonic, so that is the largest root).
    double reach2 = 0;
    for (int i = 0; i < patch.loop_length; ++i) {
      const int s = patch.loop[i];
      if (is_face_diagonal(s) && !((in.kept_faces >> face_of_diagonal(s)) & 1)) {
        removed[removed_count++] = uint8_t(s);
        const Vec3d& before = pos[patch.loop[(i + patch.loop_length - 1) % patch.loop_length]];
        const Vec3d& after = pos[patch.loop[(i + 1) % patch.loop_length]];
        reach2 = std::max(reach2, point_segment_distance2(pos[s], before, after));
        continue;
      }
      at[k] = uint8_t(i);
      loop[k] = uint8_t(s);
      faces[k] = faces_at(s);
      if (faces[k] != faces_of_slot(s)) return fail();
      ++k;
    }
    // Side i runs from loop[i] to loop[i + 1] (side k - 1 closes the loop); merged when it
    // replaces a left-out crossing.
    bool merged_side[kMaxSlotsInLoop] = {};
    for (int i = 0; i < k; ++i)
      merged_side[i] = (at[(i + 1) % k] - at[i] + patch.loop_length) % patch.loop_length != 1;
    for (int i = 0; i < patch.interior_count; ++i) removed[removed_count++] = patch.interior[i];

    // The pieces of this patch.
    Tri8 own[12];
    int own_count = 0;
    for (int t = 0; t < piece_count; ++t)
      if (c.patch_of_slot[pieces[t][0]] == p) own[own_count++] = pieces[t];
    NearTriangle near_own[12];

    if (removed_count == 0) {  // nothing to leave out: the pieces already triangulate the boundary
      for (int t = 0; t < own_count; ++t) {
        result[result_count] = own[t];
        result_new[result_count++] = 0;
      }
      continue;
    }
    if (k < 3 || k > kMaxLoop) return fail();
    for (int t = 0; t < own_count; ++t) near_own[t].set(pos, own[t], dev);

    // Which triangles (i < j < l) the face rules allow: no three corners on one face, and no
    // chord (two corners not adjacent on the boundary) between corners sharing a face.
    auto adjacent = [&](int i, int j) { return j - i == 1 || (i == 0 && j == k - 1); };
    auto chord_ok = [&](int i, int j) { return adjacent(i, j) || (faces[i] & faces[j]) == 0; };
    // A triangle's shape, (area / sum of squared edges)^2 (the square of a quality that is 1
    // for an equilateral triangle and 0 for a flat one, up to a constant), or -1 where the face
    // rules forbid it.
    double edge2[kMaxLoop][kMaxLoop];
    for (int i = 0; i < k; ++i)
      for (int j = i + 1; j < k; ++j) edge2[i][j] = dot(pos[loop[j]] - pos[loop[i]], pos[loop[j]] - pos[loop[i]]);
    double tri_quality[kMaxLoop][kMaxLoop][kMaxLoop];
    for (int i = 0; i < k; ++i)
      for (int j = i + 1; j < k; ++j)
        for (int l = j + 1; l < k; ++l) {
          const bool ok = (faces[i] & faces[j] & faces[l]) == 0 && chord_ok(i, j) && chord_ok(j, l) && chord_ok(i, l);
          const double edges = edge2[i][j] + edge2[j][l] + edge2[i][l];
          tri_quality[i][j][l] =
              ok && edges > 0 ? squared(cross(pos[loop[j]] - pos[loop[i]], pos[loop[l]] - pos[loop[i]])) / (edges * edges) : -1;
        }
    const auto& candidates = triangulations().of_size[k];
    // Candidates by their worst triangle's shape, best first (ties by index: deterministic).
    struct Order {
      double key;
      int index;
      bool operator<(const Order& o) const { return key != o.key ? key < o.key : index < o.index; }
    } order[132];
    int order_count = 0;
    for (int t = 0; t < int(candidates.size()); ++t) {
      double worst = HUGE_VAL;
      for (const auto& tri : candidates[size_t(t)]) worst = std::min(worst, tri_quality[tri[0]][tri[1]][tri[2]]);
      if (worst > 0) order[order_count++] = {-worst, t};
    }
    if (order_count > 1) std::sort(order, order + order_count);

    // Where the patch is flat, the deviation tests below follow from exact orientations. Project
    // along the axis k nearest the pieces' normal: when every piece and every new triangle turns
    // the same way there, each surface is an orientation-preserving map of a disk onto the plane,
    // covering each point as often as its boundary curve winds around it. The two curves differ
    // only where a face-diagonal crossing d is left out between its neighbours a and b: by the
    // triangle a d b, which lies in d's face, so on a face parallel to k it projects onto a line
    // (no winding number changes) and on one orthogonal to k it is flat in the plane. So a
    // point of either surface has a point of the other, or of such a triangle, on its line along
    // k. All of them are linear on triangles of the patch's crossings, whose heights along k over
    // one plane lie in a range W, so that point lies within W. A point of a triangle a d b lies
    // within H of a d or d b, and of a b, H the largest distance from a left-out d to the
    // segment between its neighbours (its height over a b bounds both); so does d. With W + H
    // below the deviation (a margin for rounding), every point the tests below sample passes
    // them (a point within the deviation of a triangle lies in its grown box and near its plane
    // too), and facing is tested as there, against every piece: the candidate is the one those
    // tests would take, found without them. The exact tests (collinear, crossing) still run.
    int flat_axis = -1, flat_sign = 0;
    {
      Vec3d normal;
      for (int t = 0; t < own_count; ++t) normal += near_own[t].normal_vector();
      const int fk = dominant_axis(normal);
      const int fi = (fk + 1) % 3, fj = (fk + 2) % 3, fs = normal[fk] > 0 ? 1 : -1;
      bool flat = std::fabs(normal[fk]) > 0;
      for (int t = 0; t < own_count && flat; ++t) {
        const Vec3d &a = pos[own[t][0]], &b = pos[own[t][1]], &d = pos[own[t][2]];
        if (exact::orient2d(a[fi], a[fj], b[fi], b[fj], d[fi], d[fj]) != fs) flat = false;
      }
      if (flat) {
        Vec3d centre;
        const int crossings = patch.loop_length + patch.interior_count;
        for (int i = 0; i < patch.loop_length; ++i) centre += pos[patch.loop[i]];
        for (int i = 0; i < patch.interior_count; ++i) centre += pos[patch.interior[i]];
        centre = centre / double(crossings);
        // The crossings' heights along k over the plane through the centre.
        double lowest = HUGE_VAL, highest = -HUGE_VAL;
        for (int i = 0; i < crossings; ++i) {
          const Vec3d& q = pos[i < patch.loop_length ? patch.loop[i] : patch.interior[i - patch.loop_length]];
          const double height = dot(normal, q - centre) / normal[fk];
          lowest = std::min(lowest, height);
          highest = std::max(highest, height);
        }
        flat = (highest - lowest) + std::sqrt(reach2) <= 0.999 * dev;  // W + H
      }
      if (flat && !in.sampled_tests_only) {
        flat_axis = fk;
        flat_sign = fs;
      }
    }

    bool found = false;
    for (int o = 0; o < order_count && !found; ++o) {
      const auto& cand = candidates[size_t(order[o].index)];
      const int m = int(cand.size());
      Tri8 tris[kMaxLoop - 2];
      for (int t = 0; t < m; ++t) tris[t] = {loop[cand[size_t(t)][0]], loop[cand[size_t(t)][1]], loop[cand[size_t(t)][2]]};
      bool ok = true;
      for (int t = 0; t < m && ok; ++t)
        if (exact::collinear(pos[tris[t][0]], pos[tris[t][1]], pos[tris[t][2]])) ok = false;
      if (!ok) continue;
      NearTriangle near_new[kMaxLoop - 2];
      for (int t = 0; t < m; ++t) near_new[t].set(pos, tris[t], dev);
      bool proven = flat_axis >= 0;
      for (int t = 0; t < m && proven; ++t) {
        const int fi = (flat_axis + 1) % 3, fj = (flat_axis + 2) % 3;
        const Vec3d &a = pos[tris[t][0]], &b = pos[tris[t][1]], &d = pos[tris[t][2]];
        if (exact::orient2d(a[fi], a[fj], b[fi], b[fj], d[fi], d[fj]) != flat_sign) proven = false;
        const Vec3d facing = near_new[t].normal_vector();
        for (int u = 0; u < own_count && proven; ++u)
          if (!(dot(facing, near_own[u].normal_vector()) > 0)) proven = false;
      }
      // The left-out crossings lie within the deviation of the new triangles.
      for (int r = 0; r < removed_count && ok && !proven; ++r) {
        bool near = false;
        for (int t = 0; t < m && !near; ++t) near = near_new[t].near(pos[removed[r]], dev, dev2);
        ok = near;
      }
      if (!ok) continue;
      // Points of the new triangles lie within the deviation of the pieces; each new triangle's
      // centre lies near a piece that faces its way.
      auto near_pieces = [&](const Vec3d& q, const Vec3d* facing) {
        for (int t = 0; t < own_count; ++t)
          if ((!facing || dot(*facing, near_own[t].normal_vector()) > 0) && near_own[t].near(q, dev, dev2)) return true;
        return false;
      };
      for (int t = 0; t < m && ok && !proven; ++t) {
        const Vec3d &a = pos[tris[t][0]], &b = pos[tris[t][1]], &d = pos[tris[t][2]];
        const Vec3d facing = near_new[t].normal_vector();
        if (!near_pieces((a + b + d) / 3.0, &facing)) {
          ok = false;
          break;
        }
        for (int e = 0; e < 3 && ok; ++e) {
          const int i = cand[size_t(t)][size_t(e)], j = cand[size_t(t)][size_t((e + 1) % 3)];
          const int lo = std::min(i, j), hi = std::max(i, j);
          const bool side = adjacent(lo, hi);
          // Chords are shared by two new triangles: tested once, from the one with the lower index.
          if (!side || merged_side[lo == 0 && hi == k - 1 ? k - 1 : lo])
            if (!near_pieces((pos[loop[i]] + pos[loop[j]]) * 0.5, nullptr)) ok = false;
        }
      }
      if (!ok) continue;
      // No two new triangles meet beyond what they share.
      for (int t = 0; t < m && ok; ++t)
        for (int u = t + 1; u < m && ok; ++u) {
          const std::array<uint32_t, 3> ti{tris[t][0], tris[t][1], tris[t][2]}, ui{tris[u][0], tris[u][1], tris[u][2]};
          if (exact::faces_intersect({pos[ti[0]], pos[ti[1]], pos[ti[2]]}, ti, {pos[ui[0]], pos[ui[1]], pos[ui[2]]}, ui))
            ok = false;
        }
      if (!ok) continue;
      for (int t = 0; t < m; ++t) {
        result[result_count] = tris[t];
        result_new[result_count++] = 1;
      }
      found = true;
      if (proven && in.proven_candidates) ++*in.proven_candidates;
      if (lost) {
        // Pieces minus merged triangles plus the face triangles (a, b, d) of the merged sides
        // a -> b that replace a -> d -> b: that chain has no boundary, so its volume is the loss.
        double loss6 = 0;
        for (int t = 0; t < own_count; ++t) loss6 += cone6(own[t][0], own[t][1], own[t][2]);
        for (int t = 0; t < m; ++t) loss6 -= cone6(tris[t][0], tris[t][1], tris[t][2]);
        for (int i = 0; i < k; ++i)
          for (int j = at[i] + 1; j < (i + 1 < k ? at[i + 1] : at[0] + patch.loop_length); ++j)
            loss6 += cone6(loop[i], loop[(i + 1) % k], patch.loop[j % patch.loop_length]);
        for (int i = 0; i < k; ++i) {
          lost->slots[lost->count] = loop[i];
          lost->volume6[lost->count++] = loss6 / k;
        }
      }
    }
    if (!found) return fail();
  }

  // Triangles of different patches do not meet at all (pairs of pieces are disjoint already).
  if (c.patch_count > 1)
    for (int t = 0; t < result_count; ++t)
      for (int u = t + 1; u < result_count; ++u) {
        if (!result_new[t] && !result_new[u]) continue;
        if (c.patch_of_slot[result[t][0]] == c.patch_of_slot[result[u][0]]) continue;
        const std::array<uint32_t, 3> ti{result[t][0], result[t][1], result[t][2]},
            ui{result[u][0], result[u][1], result[u][2]};
        if (exact::faces_intersect({pos[ti[0]], pos[ti[1]], pos[ti[2]]}, ti, {pos[ui[0]], pos[ui[1]], pos[ui[2]]}, ui))
          return fail();
      }
  out.insert(out.end(), result, result + result_count);
  return true;
}

}  // namespace lacuna::cube_surface
