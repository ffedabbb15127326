// Convex polygon and polyhedron clipping by half-planes and half-spaces, with each edge or face labelled by
// the cut that made it: the Voronoi cells of src/voronoi are built with these. Internal to src/voronoi.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace lacuna {
namespace voronoi {
namespace detail {

using V2 = std::array<double, 2>;
using V3 = std::array<double, 3>;

// A convex polygon; label[i] is the generator whose bisector carries the edge from vertex i to i + 1.
struct Polygon2 {
  std::vector<V2> v;
  std::vector<int> label;
};

// Vertices within this distance (torus units) of a clipping line or plane count as on it, so that a second
// cut along (nearly) the same plane, from a generator that rounding left beside another, changes nothing.
inline constexpr double kOnPlane = 1e-13;

// Keeps the part where nx * x + ny * y <= c; false when nothing was cut away.
inline bool clip(Polygon2& poly, double nx, double ny, double c, int label) {
  const size_t count = poly.v.size();
  if (count == 0) return false;
  const double eps = kOnPlane * std::hypot(nx, ny);
  std::vector<double> f(count);
  bool any_out = false;
  for (size_t i = 0; i < count; ++i) {
    f[i] = nx * poly.v[i][0] + ny * poly.v[i][1] - c;
    any_out = any_out || f[i] > eps;
  }
  if (!any_out) return false;
  Polygon2 out;
  for (size_t i = 0; i < count; ++i) {
    const size_t k = (i + 1) % count;
    const bool in_a = f[i] <= eps, in_b = f[k] <= eps;
    if (in_a) {
      out.v.push_back(poly.v[i]);
      out.label.push_back(poly.label[i]);
    }
    if (in_a != in_b) {
      const double t = std::clamp(f[i] / (f[i] - f[k]), 0.0, 1.0);
      const V2 p{poly.v[i][0] + t * (poly.v[k][0] - poly.v[i][0]), poly.v[i][1] + t * (poly.v[k][1] - poly.v[i][1])};
      out.v.push_back(p);
      // Leaving: the new edge runs along the clipping line; entering: along the old edge.
      out.label.push_back(in_a ? label : poly.label[i]);
    }
  }
  if (out.v.size() < 3) out = Polygon2{};
  poly = std::move(out);
  return true;
}

inline double area(const Polygon2& poly) {
  double a = 0;
  for (size_t i = 0, count = poly.v.size(); i < count; ++i) {
    const V2& p = poly.v[i];
    const V2& q = poly.v[(i + 1) % count];
    a += p[0] * q[1] - p[1] * q[0];
  }
  return a / 2;
}

// A convex polyhedron as its faces (vertex cycles of either orientation), each labelled with the generator
// whose bisector carries it.
struct Polyhedron {
  std::vector<std::vector<V3>> faces;
  std::vector<int> label;
};

inline V3 sub3(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline V3 cross3(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot3(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

inline V3 area_vector(const std::vector<V3>& face) {
  V3 a{0, 0, 0};
  for (size_t i = 0, count = face.size(); i < count; ++i) {
    const V3 c = cross3(face[i], face[(i + 1) % count]);
    for (int j = 0; j < 3; ++j) a[size_t(j)] += c[size_t(j)] / 2;
  }
  return a;
}

// Keeps the part where dot(normal, x) <= c; the cut is closed by a new face labelled `label`. False when
// nothing was cut away.
inline bool clip(Polyhedron& poly, const V3& normal, double c, int label) {
  const double eps = kOnPlane * std::sqrt(dot3(normal, normal));
  bool any_out = false;
  for (const auto& face : poly.faces)
    for (const V3& p : face) any_out = any_out || dot3(normal, p) - c > eps;
  if (!any_out) return false;
  Polyhedron out;
  std::vector<V3> cap;
  for (size_t fi = 0; fi < poly.faces.size(); ++fi) {
    const auto& face = poly.faces[fi];
    const size_t count = face.size();
    std::vector<double> f(count);
    for (size_t i = 0; i < count; ++i) f[i] = dot3(normal, face[i]) - c;
    std::vector<V3> kept;
    for (size_t i = 0; i < count; ++i) {
      const size_t k = (i + 1) % count;
      const bool in_a = f[i] <= eps, in_b = f[k] <= eps;
      if (in_a) {
        kept.push_back(face[i]);
        if (f[i] >= -eps) cap.push_back(face[i]);
      }
      if (in_a != in_b) {
        const double t = std::clamp(f[i] / (f[i] - f[k]), 0.0, 1.0);
        const V3 p{face[i][0] + t * (face[k][0] - face[i][0]), face[i][1] + t * (face[k][1] - face[i][1]),
                   face[i][2] + t * (face[k][2] - face[i][2])};
        kept.push_back(p);
        cap.push_back(p);
      }
    }
    if (kept.size() >= 3) {
      out.faces.push_back(std::move(kept));
      out.label.push_back(poly.label[fi]);
    }
  }
  if (cap.size() >= 3) {
    // The cap is convex and lies in the plane: order its points by angle about their mean.
    V3 centre{0, 0, 0};
    for (const V3& p : cap)
      for (int j = 0; j < 3; ++j) centre[size_t(j)] += p[size_t(j)] / double(cap.size());
    // The axis least aligned with the normal.
    const double ax = std::fabs(normal[0]), ay = std::fabs(normal[1]), az = std::fabs(normal[2]);
    const V3 helper = ax <= ay && ax <= az ? V3{1, 0, 0} : (ay <= az ? V3{0, 1, 0} : V3{0, 0, 1});
    const V3 e1 = cross3(normal, helper);
    const V3 e2 = cross3(normal, e1);
    std::vector<std::pair<double, V3>> sorted;
    for (const V3& p : cap) {
      const V3 r = sub3(p, centre);
      sorted.push_back({std::atan2(dot3(r, e2), dot3(r, e1)), p});
    }
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<V3> face;
    for (const auto& s : sorted) face.push_back(s.second);
    out.faces.push_back(std::move(face));
    out.label.push_back(label);
  }
  if (out.faces.size() < 4) out = Polyhedron{};
  poly = std::move(out);
  return true;
}

// Pyramids from a point inside the convex polyhedron.
inline double volume(const Polyhedron& poly, const V3& inside) {
  double v = 0;
  for (const auto& face : poly.faces) v += std::fabs(dot3(area_vector(face), sub3(face[0], inside))) / 3;
  return v;
}

}  // namespace detail
}  // namespace voronoi
}  // namespace lacuna
