#include "bcifs/realize.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <tuple>

#include "errors.h"
#include "util/bitmap_font.h"

namespace lacuna {
namespace bcifs {
namespace {

constexpr double kMaxLeaves = 2e7;
constexpr int kBoxRaster = 1024;

// Where a point lies along an edge: the lengths before (u) and after (v) it, in units of the edge.
struct Split {
  double u = 0, v = 1;
};

// Sub-edges of edge type e: length of one sub-edge and of one gap (fractions of the edge), count.
struct Layout {
  int count = 1;
  double sub = 1, gap = 0;
};

Layout layout_of(const EdgeType& e, double gap_fraction) {
  if (e.delay >= 2) return {1, 1, 0};
  if (e.kind == EdgeKind::kBezier) return {e.n, 1, 0};  // integer steps: the weights are k/n exactly
  return {e.n, (1 - gap_fraction) / e.n, gap_fraction / (e.n - 1)};
}

double run_length(const Layout& l, double subs, double gaps) { return subs * l.sub + gaps * l.gap; }

// Boundary point `index` (2k: start of sub-edge k, 2k + 1: its end).
Split boundary_split(const Layout& l, int index) {
  const int k = index / 2;
  if (index % 2 == 0) return {run_length(l, k, k), run_length(l, l.count - k, l.count - 1 - k)};
  return {run_length(l, k + 1, k), run_length(l, l.count - k - 1, l.count - 1 - k)};
}

// The point after sub-edge k: the joint of two Bézier sub-edges or the midpoint of a Cantor gap.
Split joint_split(const Layout& l, int k) {
  return {run_length(l, k + 1, k + 0.5), run_length(l, l.count - k - 1, l.count - k - 1.5)};
}

Vec2d combine(const Vec2d& a, const Vec2d& b, const Split& s) {
  const double total = s.u + s.v;
  const double wa = s.v / total, wb = s.u / total;
  return {wa * a.x + wb * b.x, wa * a.y + wb * b.y};
}

Vec2d lerp(const Vec2d& a, const Vec2d& b, double t) { return {(1 - t) * a.x + t * b.x, (1 - t) * a.y + t * b.y}; }

// Whether the end points of an edge are in the fixed order curves are evaluated in (lexicographic).
bool in_order(const Vec2d& a, const Vec2d& b) { return a.x < b.x || (a.x == b.x && a.y <= b.y); }

// The point at split s of the quadratic Bézier (a, bend, b), evaluated from the end point that comes first so
// that the face across a shared edge, which sees (b, bend, a) at the swapped split, gets the same doubles.
Vec2d curve_point(const Vec2d& a, const Vec2d& bend, const Vec2d& b, const Split& s) {
  if (!in_order(a, b)) return curve_point(b, bend, a, {s.v, s.u});
  const double total = s.u + s.v, ta = s.v / total, tb = s.u / total;
  const double wa = ta * ta, wm = 2 * ta * tb, wb = tb * tb;
  return {wa * a.x + wm * bend.x + wb * b.x, wa * a.y + wm * bend.y + wb * b.y};
}

// The bend of the piece of the curve (a, bend, b) between splits s0 and s1: its blossom b(t0, t1).
Vec2d curve_piece_bend(const Vec2d& a, const Vec2d& bend, const Vec2d& b, const Split& s0, const Split& s1) {
  if (!in_order(a, b)) return curve_piece_bend(b, bend, a, {s1.v, s1.u}, {s0.v, s0.u});
  const double t0 = s0.u + s0.v, t1 = s1.u + s1.v;
  const double a0 = s0.v / t0, b0 = s0.u / t0, a1 = s1.v / t1, b1 = s1.u / t1;
  const double wa = a0 * a1, wm = a0 * b1 + b0 * a1, wb = b0 * b1;
  return {wa * a.x + wm * bend.x + wb * b.x, wa * a.y + wm * bend.y + wb * b.y};
}

// A point on edge e of a face: on its curve when it has a bend, on the chord otherwise.
Vec2d edge_point(const std::vector<Vec2d>& control, const std::vector<Bend>& bends, int e, const Split& s) {
  const size_t n = control.size();
  const Vec2d& a = control[size_t(e) % n];
  const Vec2d& b = control[(size_t(e) + 1) % n];
  if (!bends.empty() && bends[size_t(e) % n]) return curve_point(a, *bends[size_t(e) % n], b, s);
  return combine(a, b, s);
}

void check_bends(const FaceRule& rule, const std::vector<Bend>& bends) {
  if (!bends.empty() && bends.size() != rule.face.boundary.size())
    throw InvalidInput("bends of " + to_string(rule.face) + ": expected none or " +
                       std::to_string(rule.face.boundary.size()) + " (one per edge), got " + std::to_string(bends.size()));
  for (const Bend& b : bends)
    if (b && !(std::isfinite(b->x) && std::isfinite(b->y)))
      throw InvalidInput("bends of " + to_string(rule.face) + ": a bend is not finite");
}

template <class T>
std::vector<T> rotated(const std::vector<T>& written, int shift) {
  const size_t n = written.size();
  std::vector<T> out(n);
  for (size_t j = 0; j < n; ++j) out[j] = written[(j + size_t(shift)) % n];
  return out;
}

const GeometryOptions& options_for(const RealizeOptions& options, int type) {
  const auto found = options.per_type.find(type);
  return found == options.per_type.end() ? options.defaults : found->second;
}

void check_control(const FaceRule& rule, const std::vector<Vec2d>& control) {
  if (control.size() != rule.face.boundary.size())
    throw InvalidInput("control polygon of " + to_string(rule.face) + ": expected " +
                       std::to_string(rule.face.boundary.size()) + " points (one per boundary vertex), got " +
                       std::to_string(control.size()));
  for (const Vec2d& p : control)
    if (!std::isfinite(p.x) || !std::isfinite(p.y))
      throw InvalidInput("control polygon of " + to_string(rule.face) + ": a point is not finite");
}

void check_type(const RuleSet& rules, int type) {
  if (type < 0 || type >= int(rules.rules.size()))
    throw InvalidInput("face type " + std::to_string(type) + " is not in the rule set");
}

// The control polygon of a sub-face in its type's canonical order.
std::vector<Vec2d> canonical_polygon(const SubFace& sub, const std::vector<Vec2d>& written) {
  return rotated(written, sub.shift);
}

using EdgeKey = std::array<double, 4>;

BoxCount fit(const std::vector<uint8_t>& mask, int size) {
  BoxCount out;
  for (int box = size / 16; box >= 1; box /= 2) {
    const int boxes = size / box;
    long count = 0;
    for (int by = 0; by < boxes; ++by)
      for (int bx = 0; bx < boxes; ++bx) {
        bool hit = false;
        for (int y = by * box; y < (by + 1) * box && !hit; ++y)
          for (int x = bx * box; x < (bx + 1) * box; ++x)
            if (mask[size_t(y) * size_t(size) + size_t(x)]) {
              hit = true;
              break;
            }
        count += hit;
      }
    out.log_inverse_size.push_back(std::log(double(boxes)));
    out.log_count.push_back(std::log(double(std::max(count, 1L))));
  }
  const double n = double(out.log_count.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < out.log_count.size(); ++i) {
    sx += out.log_inverse_size[i];
    sy += out.log_count[i];
    sxx += out.log_inverse_size[i] * out.log_inverse_size[i];
    sxy += out.log_inverse_size[i] * out.log_count[i];
  }
  out.dimension = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return out;
}

// Drawing on an RGB canvas.
struct Canvas {
  int width, height;
  std::vector<uint8_t> rgb;
  void set(int x, int y, std::array<uint8_t, 3> c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    const size_t at = 3 * (size_t(height - 1 - y) * size_t(width) + size_t(x));  // y up
    rgb[at] = c[0];
    rgb[at + 1] = c[1];
    rgb[at + 2] = c[2];
  }
  void line(double x0, double y0, double x1, double y1, std::array<uint8_t, 3> c) {
    const int steps = int(std::ceil(std::max(std::fabs(x1 - x0), std::fabs(y1 - y0)))) + 1;
    for (int s = 0; s <= steps; ++s) {
      const double t = double(s) / steps;
      set(int(std::lround(x0 + t * (x1 - x0))), int(std::lround(y0 + t * (y1 - y0))), c);
    }
  }
  void marker(double x, double y, std::array<uint8_t, 3> c) {
    for (int dy = -3; dy <= 3; ++dy)
      for (int dx = -3; dx <= 3; ++dx) set(int(std::lround(x)) + dx, int(std::lround(y)) + dy, c);
  }
};

}  // namespace

void validate(const GeometryOptions& options) {
  auto check = [](double value, const char* name) {
    if (!(value > 0 && value < 1))
      throw InvalidInput(std::string("geometry option ") + name + " must be in (0, 1), got " + message_number(value));
  };
  check(options.gap_fraction, "gap_fraction");
  check(options.lacuna_scale, "lacuna_scale");
  check(options.notch_depth, "notch_depth");
}

const std::vector<std::string>& realization_names() {
  static const std::vector<std::string> names{"default", "paper"};
  return names;
}

GeometryOptions realization_preset(const std::string& name) {
  GeometryOptions options;
  if (name == "default") return options;
  if (name == "paper") {
    options.lacuna_scale = 0.55;
    options.gap_fraction = 0.2;
    options.notch_depth = 0.7;
    return options;
  }
  std::string known;
  for (const std::string& n : realization_names()) known += (known.empty() ? "" : ", ") + n;
  throw InvalidInput("unknown realization '" + name + "': expected one of " + known);
}

Vec2d vertex_position(const FaceRule& rule, const std::vector<Vec2d>& control, const VertexRef& vertex,
                      const GeometryOptions& options, const std::vector<Bend>& bends) {
  check_control(rule, control);
  check_bends(rule, bends);
  const int n = int(control.size());
  auto corner = [&](int k) { return control[size_t((k % n + n) % n)]; };
  auto lacuna_corner = [&](int k) {
    Vec2d c{0, 0};
    for (const Vec2d& p : control) c = c + p;
    c = c * (1.0 / n);
    return lerp(c, corner(k), options.lacuna_scale);
  };
  auto edge_layout = [&](int edge) { return layout_of(rule.face.boundary[size_t(edge)], options.gap_fraction); };
  auto foot = [&](int edge, int k) {
    return combine(lacuna_corner(edge), lacuna_corner(edge + 1), joint_split(edge_layout(edge), k));
  };
  switch (vertex.kind) {
    case VertexKind::kBoundary:
      return edge_point(control, bends, vertex.edge, boundary_split(edge_layout(vertex.edge), vertex.index));
    case VertexKind::kLacunaCorner: return lacuna_corner(vertex.index);
    case VertexKind::kLacunaEdge: return foot(vertex.edge, vertex.index);
    case VertexKind::kNotchApex: {
      const Vec2d mid = edge_point(control, bends, vertex.edge, joint_split(edge_layout(vertex.edge), vertex.index));
      return lerp(mid, foot(vertex.edge, vertex.index), options.notch_depth);
    }
  }
  return {};
}

std::vector<std::vector<Vec2d>> subface_polygons(const FaceRule& rule, const std::vector<Vec2d>& control,
                                                 const GeometryOptions& options, const std::vector<Bend>& bends) {
  check_control(rule, control);
  std::vector<std::vector<Vec2d>> out;
  out.reserve(rule.subfaces.size());
  for (const SubFace& sub : rule.subfaces) {
    std::vector<Vec2d> polygon;
    polygon.reserve(sub.vertices.size());
    for (const VertexRef& v : sub.vertices) polygon.push_back(vertex_position(rule, control, v, options, bends));
    out.push_back(std::move(polygon));
  }
  return out;
}

std::vector<std::vector<Bend>> subface_bends(const FaceRule& rule, const std::vector<Vec2d>& control,
                                             const GeometryOptions& options, const std::vector<Bend>& bends) {
  check_control(rule, control);
  check_bends(rule, bends);
  std::vector<std::vector<Bend>> out(rule.subfaces.size());
  if (bends.empty()) return out;
  const size_t n = control.size();
  for (size_t s = 0; s < rule.subfaces.size(); ++s) {
    const SubFace& sub = rule.subfaces[s];
    out[s].resize(sub.incidence.size());
    for (size_t j = 0; j < sub.incidence.size(); ++j) {
      const Incidence& inc = sub.incidence[j];
      if (inc.role != EdgeRole::kParent || !bends[size_t(inc.parent_edge)]) continue;
      // Sub-edge k of the parent edge runs from boundary point 2k to 2k + 1, in the parent edge's direction.
      const Layout l = layout_of(rule.face.boundary[size_t(inc.parent_edge)], options.gap_fraction);
      out[s][j] = curve_piece_bend(control[size_t(inc.parent_edge)], *bends[size_t(inc.parent_edge)],
                                   control[(size_t(inc.parent_edge) + 1) % n], boundary_split(l, 2 * inc.sub_edge),
                                   boundary_split(l, 2 * inc.sub_edge + 1));
    }
  }
  return out;
}

std::vector<Vec2d> outline(const Leaf& leaf) {
  if (leaf.bends.empty()) return leaf.polygon;
  std::vector<Vec2d> out;
  const size_t n = leaf.polygon.size();
  for (size_t j = 0; j < n; ++j) {
    out.push_back(leaf.polygon[j]);
    if (!leaf.bends[j]) continue;
    for (int i = 1; i < kCurveSegments; ++i)
      out.push_back(curve_point(leaf.polygon[j], *leaf.bends[j], leaf.polygon[(j + 1) % n],
                                {double(i), double(kCurveSegments - i)}));
  }
  return out;
}

std::vector<Vec2d> lacuna_polygon(const FaceRule& rule, const std::vector<Vec2d>& control,
                                  const GeometryOptions& options) {
  std::vector<Vec2d> out;
  if (rule.face.delay >= 2) return out;
  // Sub-face r's El edge runs from the foot of its end cut to the foot of its start cut; the end cuts of the
  // sub-faces in order go counter-clockwise.
  for (const SubFace& s : rule.subfaces)
    for (size_t j = 0; j < s.incidence.size(); ++j)
      if (s.incidence[j].role == EdgeRole::kLacuna) out.push_back(vertex_position(rule, control, s.vertices[j], options));
  return out;
}

std::vector<Leaf> realize(const RuleSet& rules, int type, const std::vector<Vec2d>& control, int levels,
                          const RealizeOptions& options, const std::vector<Bend>& bends) {
  check_type(rules, type);
  if (levels < 0) throw InvalidInput("realize: levels must be >= 0, got " + std::to_string(levels));
  check_control(rules.rules[size_t(type)], control);
  check_bends(rules.rules[size_t(type)], bends);
  // A leaf keeps bends only while one of its edges is curved.
  auto trimmed = [](std::vector<Bend> b) {
    for (const Bend& x : b)
      if (x) return b;
    return std::vector<Bend>{};
  };
  validate(options.defaults);
  for (const auto& entry : options.per_type) validate(entry.second);
  std::vector<Leaf> leaves{Leaf{control, type, trimmed(bends)}};
  for (int level = 0; level < levels; ++level) {
    double next_count = 0;
    for (const Leaf& leaf : leaves) next_count += double(rules.rules[size_t(leaf.type)].subfaces.size());
    if (next_count > kMaxLeaves)
      throw ResourceLimit("realize: level " + std::to_string(level + 1) + " would hold " +
                          std::to_string(long(next_count)) + " leaves (at most 20000000); use fewer levels");
    std::vector<Leaf> next;
    next.reserve(size_t(next_count));
    for (const Leaf& leaf : leaves) {
      const FaceRule& rule = rules.rules[size_t(leaf.type)];
      const GeometryOptions& o = options_for(options, leaf.type);
      const std::vector<std::vector<Vec2d>> polygons = subface_polygons(rule, leaf.polygon, o, leaf.bends);
      const std::vector<std::vector<Bend>> sub_bends = subface_bends(rule, leaf.polygon, o, leaf.bends);
      for (size_t s = 0; s < polygons.size(); ++s)
        next.push_back(Leaf{canonical_polygon(rule.subfaces[s], polygons[s]), rule.subfaces[s].type,
                            trimmed(rotated(sub_bends[s], rule.subfaces[s].shift))});
    }
    leaves.swap(next);
  }
  return leaves;
}

std::vector<std::vector<Leaf>> realize_assembly(const RuleSet& rules, const Assembly& assembly,
                                                const std::vector<std::vector<Vec2d>>& controls, int levels,
                                                const RealizeOptions& options,
                                                const std::vector<std::vector<Bend>>& bends) {
  if (!bends.empty() && bends.size() != assembly.faces.size())
    throw InvalidInput("realize_assembly: " + std::to_string(assembly.faces.size()) + " faces but " +
                       std::to_string(bends.size()) + " lists of bends");
  validate(assembly);
  if (controls.size() != assembly.faces.size())
    throw InvalidInput("realize_assembly: " + std::to_string(assembly.faces.size()) + " faces but " +
                       std::to_string(controls.size()) + " control polygons");
  for (size_t f = 0; f < controls.size(); ++f)
    if (controls[f].size() != assembly.faces[f].boundary.size())
      throw InvalidInput("realize_assembly: face " + std::to_string(f) + " has " +
                         std::to_string(assembly.faces[f].boundary.size()) + " edges but " +
                         std::to_string(controls[f].size()) + " control points");
  for (size_t s = 0; s < assembly.shared.size(); ++s) {
    const SharedEdge& e = assembly.shared[s];
    const auto& a = controls[size_t(e.face_a)];
    const auto& b = controls[size_t(e.face_b)];
    const Vec2d a0 = a[size_t(e.edge_a)], a1 = a[(size_t(e.edge_a) + 1) % a.size()];
    const Vec2d b0 = b[size_t(e.edge_b)], b1 = b[(size_t(e.edge_b) + 1) % b.size()];
    if (!(a0 == b1 && a1 == b0))
      throw InvalidInput("realize_assembly: shared edge " + std::to_string(s) +
                         ": the two sides' control points differ (face_a's edge must be face_b's edge reversed)");
    auto bend_of = [&](int face, int edge) {
      return bends.empty() || bends[size_t(face)].empty() ? Bend{} : bends[size_t(face)][size_t(edge)];
    };
    if (!(bend_of(e.face_a, e.edge_a) == bend_of(e.face_b, e.edge_b)))
      throw InvalidInput("realize_assembly: shared edge " + std::to_string(s) + ": the two sides bend it differently");
  }
  std::vector<std::vector<Leaf>> out;
  for (size_t f = 0; f < assembly.faces.size(); ++f) {
    const int type = find_type(rules, assembly.faces[f]);
    if (type < 0)
      throw InvalidInput("realize_assembly: face " + std::to_string(f) + " is not in the rule set");
    const int shift = canonical_shift(assembly.faces[f].boundary);
    const std::vector<Bend> face_bends = bends.empty() || bends[f].empty() ? std::vector<Bend>{} : rotated(bends[f], shift);
    out.push_back(realize(rules, type, rotated(controls[f], shift), levels, options, face_bends));
  }
  return out;
}

std::vector<std::pair<Vec2d, Vec2d>> edge_segments(const RuleSet& rules, int type, const std::vector<Vec2d>& control,
                                                   int edge, int levels, const RealizeOptions& options) {
  check_type(rules, type);
  check_control(rules.rules[size_t(type)], control);
  std::vector<std::pair<Vec2d, Vec2d>> out;
  std::function<void(int, const std::vector<Vec2d>&, int, int)> walk = [&](int t, const std::vector<Vec2d>& poly,
                                                                           int e, int level) {
    const FaceRule& rule = rules.rules[size_t(t)];
    if (level == 0) {
      out.emplace_back(poly[size_t(e)], poly[(size_t(e) + 1) % poly.size()]);
      return;
    }
    const std::vector<std::vector<Vec2d>> polygons = subface_polygons(rule, poly, options_for(options, t));
    const int count = int(subdivide(rule.face.boundary[size_t(e)]).size());
    for (int k = 0; k < count; ++k)
      for (size_t s = 0; s < rule.subfaces.size(); ++s)
        for (size_t j = 0; j < rule.subfaces[s].incidence.size(); ++j) {
          const Incidence& inc = rule.subfaces[s].incidence[j];
          if (inc.role != EdgeRole::kParent || inc.parent_edge != e || inc.sub_edge != k) continue;
          const SubFace& sub = rule.subfaces[s];
          const int n = int(sub.boundary.size());
          walk(sub.type, canonical_polygon(sub, polygons[s]), ((int(j) - sub.shift) % n + n) % n, level - 1);
        }
  };
  walk(type, control, edge, levels);
  return out;
}

bool is_simple(const std::vector<Vec2d>& polygon) {
  const size_t n = polygon.size();
  if (n < 3) return false;
  for (size_t i = 0; i < n; ++i)
    if (polygon[i] == polygon[(i + 1) % n]) return false;
  for (size_t i = 0; i < n; ++i) {
    const Vec2d& a = polygon[i];
    const Vec2d& b = polygon[(i + 1) % n];
    for (size_t j = i + 1; j < n; ++j) {
      const Vec2d& c = polygon[j];
      const Vec2d& d = polygon[(j + 1) % n];
      if (j == i + 1 || (i == 0 && j == n - 1)) {
        // Consecutive edges share one vertex; they must not fold back onto each other.
        const Vec2d& shared = j == i + 1 ? b : a;
        const Vec2d& p = j == i + 1 ? a : b;
        const Vec2d& q = j == i + 1 ? d : c;
        if (cross2(p - shared, q - shared) == 0 && (p.x - shared.x) * (q.x - shared.x) + (p.y - shared.y) * (q.y - shared.y) > 0)
          return false;
        continue;
      }
      if (segments_intersect(a, b, c, d)) return false;
    }
  }
  return true;
}

std::vector<std::pair<Vec2d, Vec2d>> boundary_segments(const std::vector<std::vector<Vec2d>>& polygons) {
  std::map<EdgeKey, int> edges;
  for (const auto& p : polygons)
    for (size_t i = 0; i < p.size(); ++i) {
      const Vec2d& a = p[i];
      const Vec2d& b = p[(i + 1) % p.size()];
      ++edges[{a.x, a.y, b.x, b.y}];
    }
  std::vector<std::pair<Vec2d, Vec2d>> out;
  for (const auto& p : polygons)
    for (size_t i = 0; i < p.size(); ++i) {
      const Vec2d& a = p[i];
      const Vec2d& b = p[(i + 1) % p.size()];
      if (edges.find({b.x, b.y, a.x, a.y}) == edges.end()) out.emplace_back(a, b);
    }
  return out;
}

double union_perimeter(const std::vector<std::vector<Vec2d>>& polygons) {
  double length = 0;
  for (const auto& s : boundary_segments(polygons)) length += std::hypot(s.second.x - s.first.x, s.second.y - s.first.y);
  return length;
}

std::vector<std::vector<Vec2d>> polygons_of(const std::vector<Leaf>& leaves) {
  std::vector<std::vector<Vec2d>> out;
  out.reserve(leaves.size());
  for (const Leaf& leaf : leaves) out.push_back(outline(leaf));
  return out;
}

GeometricMeasures geometric_measures(const RuleSet& rules, int type, const std::vector<Vec2d>& control, int levels,
                                     const RealizeOptions& options) {
  return geometric_measures(rules, std::vector<Leaf>{Leaf{control, type, {}}}, 0, levels, options);
}

GeometricMeasures geometric_measures(const RuleSet& rules, std::vector<Leaf> leaves, int first, int last,
                                     const RealizeOptions& options, std::vector<std::vector<Vec2d>>* last_polygons) {
  if (first < 0 || last < first)
    throw InvalidInput("geometric_measures: expected 0 <= first <= last, got " + std::to_string(first) + ".." +
                       std::to_string(last));
  GeometricMeasures out;
  for (int level = 0; level <= last; ++level) {
    if (level > 0) {
      std::vector<Leaf> next;
      for (const Leaf& leaf : leaves) {
        std::vector<Leaf> children = realize(rules, leaf.type, leaf.polygon, 1, options, leaf.bends);
        next.insert(next.end(), children.begin(), children.end());
      }
      leaves.swap(next);
    }
    if (level < first) continue;
    const std::vector<std::vector<Vec2d>> polygons = polygons_of(leaves);
    double area = 0;
    for (const auto& p : polygons) area += signed_area(p);
    out.area.push_back(area);
    out.perimeter.push_back(union_perimeter(polygons));
  }
  out.first_level = first;
  if (last > first) {
    out.area_factor = std::pow(out.area.back() / out.area.front(), 1.0 / (last - first));
    out.perimeter_factor = std::pow(out.perimeter.back() / out.perimeter.front(), 1.0 / (last - first));
  }
  if (last_polygons) *last_polygons = polygons_of(leaves);
  return out;
}

Raster square_raster(const std::vector<std::vector<Vec2d>>& polygons, int size) {
  if (size < 1) throw InvalidInput("square_raster: size must be >= 1");
  double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL;
  for (const auto& p : polygons)
    for (const Vec2d& v : p) {
      x0 = std::min(x0, v.x);
      y0 = std::min(y0, v.y);
      x1 = std::max(x1, v.x);
      y1 = std::max(y1, v.y);
    }
  if (!(x1 >= x0)) throw InvalidInput("square_raster: no points");
  const double side = std::max({x1 - x0, y1 - y0, 1e-300});
  Raster r;
  r.pixel = side / size;
  r.origin = {0.5 * (x0 + x1) - 0.5 * side, 0.5 * (y0 + y1) - 0.5 * side};
  r.width = r.height = size;
  r.count.assign(size_t(size) * size_t(size), 0);
  return r;
}

void rasterize(const std::vector<std::vector<Vec2d>>& polygons, Raster& raster) {
  std::vector<double> xs;
  for (const auto& p : polygons) {
    double ymin = HUGE_VAL, ymax = -HUGE_VAL;
    for (const Vec2d& v : p) {
      ymin = std::min(ymin, v.y);
      ymax = std::max(ymax, v.y);
    }
    const int row0 = std::max(0, int(std::floor((ymin - raster.origin.y) / raster.pixel - 0.5)));
    const int row1 = std::min(raster.height - 1, int(std::ceil((ymax - raster.origin.y) / raster.pixel)));
    for (int row = row0; row <= row1; ++row) {
      const double yc = raster.origin.y + (row + 0.5) * raster.pixel;
      xs.clear();
      for (size_t i = 0; i < p.size(); ++i) {
        Vec2d lo = p[i], hi = p[(i + 1) % p.size()];
        if (lo.y == hi.y) continue;
        if (lo.y > hi.y) std::swap(lo, hi);  // both sides of a shared edge compute the same crossing
        if (yc < lo.y || yc >= hi.y) continue;
        xs.push_back(lo.x + (yc - lo.y) * (hi.x - lo.x) / (hi.y - lo.y));
      }
      std::sort(xs.begin(), xs.end());
      for (size_t k = 0; k + 1 < xs.size(); k += 2) {
        const int c0 = std::max(0, int(std::ceil((xs[k] - raster.origin.x) / raster.pixel - 0.5)));
        const int c1 = std::min(raster.width, int(std::ceil((xs[k + 1] - raster.origin.x) / raster.pixel - 0.5)));
        uint16_t* line = raster.count.data() + size_t(row) * size_t(raster.width);
        for (int c = c0; c < c1; ++c)
          if (line[c] < 65535) ++line[c];
      }
    }
  }
}

std::vector<uint8_t> mask_of(const Raster& raster) {
  std::vector<uint8_t> mask(raster.count.size());
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = raster.count[i] > 0;
  return mask;
}

double crofton_perimeter(const Raster& raster) {
  const std::vector<uint8_t> m = mask_of(raster);
  const int w = raster.width, h = raster.height;
  auto at = [&](int x, int y) -> int { return (x < 0 || y < 0 || x >= w || y >= h) ? 0 : m[size_t(y) * size_t(w) + size_t(x)]; };
  // Transitions along rows, columns and both diagonals (the image is padded with empty pixels).
  long rows = 0, cols = 0, diag = 0, anti = 0;
  for (int y = -1; y <= h; ++y)
    for (int x = -1; x <= w; ++x) {
      rows += at(x, y) != at(x + 1, y);
      cols += at(x, y) != at(x, y + 1);
      diag += at(x, y) != at(x + 1, y + 1);
      anti += at(x, y) != at(x - 1, y + 1);
    }
  const double p = raster.pixel, kPi = 3.14159265358979323846;
  return kPi / 8 * ((rows + cols) * p + (diag + anti) * p / std::sqrt(2.0));
}

BoxCount box_count(const std::vector<uint8_t>& mask, int size) {
  if (size != kBoxRaster || mask.size() != size_t(size) * size_t(size))
    throw InvalidInput("box_count: expected a 1024 x 1024 mask");
  return fit(mask, size);
}

BoxCount box_count_region(const std::vector<std::vector<Vec2d>>& polygons) {
  Raster r = square_raster(polygons, kBoxRaster);
  rasterize(polygons, r);
  return fit(mask_of(r), kBoxRaster);
}

BoxCount box_count_segments(const std::vector<std::pair<Vec2d, Vec2d>>& segments) {
  std::vector<std::vector<Vec2d>> points;
  for (const auto& s : segments) points.push_back({s.first, s.second});
  Raster r = square_raster(points, kBoxRaster);
  std::vector<uint8_t> mask(r.count.size(), 0);
  for (const auto& s : segments) {
    const double length = std::hypot(s.second.x - s.first.x, s.second.y - s.first.y);
    const int steps = int(std::ceil(4 * length / r.pixel)) + 1;
    for (int i = 0; i <= steps; ++i) {
      const Vec2d q = lerp(s.first, s.second, double(i) / steps);
      const int x = std::min(r.width - 1, std::max(0, int(std::floor((q.x - r.origin.x) / r.pixel))));
      const int y = std::min(r.height - 1, std::max(0, int(std::floor((q.y - r.origin.y) / r.pixel))));
      mask[size_t(y) * size_t(r.width) + size_t(x)] = 1;
    }
  }
  return fit(mask, kBoxRaster);
}

std::vector<double> density_map(const std::vector<uint8_t>& mask, int width, int height, int window) {
  if (width < 1 || height < 1 || mask.size() != size_t(width) * size_t(height) || window < 1)
    throw InvalidInput("density_map: mask size must be width x height and window >= 1");
  // Summed-area table with a zero first row and column.
  const size_t w1 = size_t(width) + 1;
  std::vector<double> sum(w1 * (size_t(height) + 1), 0.0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      sum[size_t(y + 1) * w1 + size_t(x + 1)] = mask[size_t(y) * size_t(width) + size_t(x)] +
                                                 sum[size_t(y) * w1 + size_t(x + 1)] +
                                                 sum[size_t(y + 1) * w1 + size_t(x)] - sum[size_t(y) * w1 + size_t(x)];
  std::vector<double> out(mask.size());
  const int half = window / 2;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int x0 = std::max(0, x - half), x1 = std::min(width, x - half + window);
      const int y0 = std::max(0, y - half), y1 = std::min(height, y - half + window);
      const double inside = sum[size_t(y1) * w1 + size_t(x1)] - sum[size_t(y0) * w1 + size_t(x1)] -
                            sum[size_t(y1) * w1 + size_t(x0)] + sum[size_t(y0) * w1 + size_t(x0)];
      out[size_t(y) * size_t(width) + size_t(x)] = inside / (double(x1 - x0) * double(y1 - y0));
    }
  return out;
}

std::vector<uint8_t> density_colours(const std::vector<double>& density) {
  std::vector<uint8_t> rgb(3 * density.size());
  for (size_t i = 0; i < density.size(); ++i) {
    const double f = std::min(1.0, std::max(0.0, density[i]));
    rgb[3 * i] = uint8_t(std::lround(255 * f));
    rgb[3 * i + 1] = 0;
    rgb[3 * i + 2] = uint8_t(std::lround(255 * (1 - f)));
  }
  return rgb;
}

uint32_t crc32(const uint8_t* data, size_t size) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t n = 0; n < 256; ++n) {
      uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  uint32_t c = 0xFFFFFFFFu;
  for (size_t i = 0; i < size; ++i) c = table[(c ^ data[i]) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

uint32_t adler32(const uint8_t* data, size_t size) {
  uint32_t a = 1, b = 0;
  for (size_t i = 0; i < size; ++i) {
    a = (a + data[i]) % 65521;
    b = (b + a) % 65521;
  }
  return (b << 16) | a;
}

std::vector<uint8_t> encode_png(int width, int height, const std::vector<uint8_t>& rgb, int level) {
  if (width < 1 || height < 1 || rgb.size() != 3 * size_t(width) * size_t(height))
    throw InvalidInput("encode_png: expected " + std::to_string(width) + " x " + std::to_string(height) +
                       " RGB pixels (3 bytes each)");
  // Raw scanlines, each with filter byte 0, then zlib: header, stored blocks, Adler-32.
  std::vector<uint8_t> raw;
  raw.reserve((3 * size_t(width) + 1) * size_t(height));
  for (int y = 0; y < height; ++y) {
    raw.push_back(0);
    raw.insert(raw.end(), rgb.begin() + long(3 * size_t(y) * size_t(width)),
               rgb.begin() + long(3 * size_t(y + 1) * size_t(width)));
  }
  std::vector<uint8_t> z;
  if (level > 0) {
    uLongf size = compressBound(uLong(raw.size()));
    z.resize(size);
    if (compress2(z.data(), &size, raw.data(), uLong(raw.size()), std::min(level, 9)) != Z_OK)
      throw InternalError("zlib could not compress a picture");
    z.resize(size);
  } else {
    z = {0x78, 0x01};
  }
  for (size_t at = 0; level <= 0 && (at < raw.size() || at == 0);) {
    const size_t len = std::min<size_t>(65535, raw.size() - at);
    const bool last = at + len == raw.size();
    z.push_back(last ? 1 : 0);
    z.push_back(uint8_t(len & 0xFF));
    z.push_back(uint8_t(len >> 8));
    z.push_back(uint8_t(~len & 0xFF));
    z.push_back(uint8_t((~len >> 8) & 0xFF));
    z.insert(z.end(), raw.begin() + long(at), raw.begin() + long(at + len));
    at += len;
    if (last) break;
  }
  if (level <= 0) {
    const uint32_t adler = adler32(raw.data(), raw.size());
    for (int s = 24; s >= 0; s -= 8) z.push_back(uint8_t(adler >> s));
  }

  std::vector<uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  auto chunk = [&png](const char* type, const std::vector<uint8_t>& data) {
    const uint32_t len = uint32_t(data.size());
    for (int s = 24; s >= 0; s -= 8) png.push_back(uint8_t(len >> s));
    std::vector<uint8_t> body(type, type + 4);
    body.insert(body.end(), data.begin(), data.end());
    png.insert(png.end(), body.begin(), body.end());
    const uint32_t crc = crc32(body.data(), body.size());
    for (int s = 24; s >= 0; s -= 8) png.push_back(uint8_t(crc >> s));
  };
  std::vector<uint8_t> header;
  for (uint32_t v : {uint32_t(width), uint32_t(height)})
    for (int s = 24; s >= 0; s -= 8) header.push_back(uint8_t(v >> s));
  header.insert(header.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, no filter method, no interlace
  chunk("IHDR", header);
  chunk("IDAT", z);
  chunk("IEND", {});
  return png;
}

void write_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb, int level) {
  const std::vector<uint8_t> png = encode_png(width, height, rgb, level);
  std::ofstream file(path, std::ios::binary);
  if (!file) throw IoError("cannot open '" + path + "' for writing");
  file.write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
  if (!file) throw IoError("cannot write '" + path + "'");
}

std::vector<uint8_t> plot_measures(const GeometricMeasures& measures, const BoxCount& boxes,
                                   const std::vector<double>& ratio, double ratio_limit, int width, int height,
                                   const PlotLabels& labels) {
  if (width < 300 || height < 150) throw InvalidInput("plot_measures: the image must be at least 300 x 150");
  Canvas canvas{width, height, std::vector<uint8_t>(3 * size_t(width) * size_t(height), 255)};
  const std::array<uint8_t, 3> black{0, 0, 0}, red{220, 0, 0}, blue{0, 0, 220}, green{0, 160, 0}, purple{140, 0, 170},
      grey{150, 150, 150};
  const int panel = width / 3;
  const int left_margin = 40, right_margin = 12, bottom_margin = 30, top_margin = 34;
  // Text with its top left at (x, y_top) in the canvas's y-up coordinates.
  auto text = [&](int x, int y_top, const std::string& s, std::array<uint8_t, 3> c) {
    draw_text(s, [&](int column, int row) { canvas.set(x + column, y_top - row, c); });
  };
  auto number = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };
  // One panel: data ranges mapped into the panel inside its margins.
  struct Frame {
    double x0, x1, y0, y1;  // data range
    int px0, px1, py0, py1;
    double x(double v) const { return px0 + (v - x0) / (x1 - x0) * (px1 - px0); }
    double y(double v) const { return py0 + (v - y0) / (y1 - y0) * (py1 - py0); }
  };
  auto make_frame = [&](double x0, double x1, double y0, double y1, int index, const std::string& title,
                        const std::string& x_label, const std::string& y_label) {
    if (!(x1 > x0)) x1 = x0 + 1;
    if (!(y1 > y0)) y1 = y0 + 1;
    const int left = index * panel;
    Frame f{x0, x1, y0, y1, left + left_margin, left + panel - right_margin, bottom_margin, height - top_margin};
    canvas.line(f.px0, f.py0, f.px1, f.py0, black);
    canvas.line(f.px0, f.py0, f.px0, f.py1, black);
    text(left + left_margin, height - 4, title, black);
    text(left + left_margin, height - 4 - kGlyphHeight - 4, y_label, black);
    text(f.px1 - text_cells(x_label), bottom_margin - 14, x_label, black);
    // The ranges at the axes' ends.
    text(f.px0 - 2, bottom_margin - 4, number(x0), black);
    text(f.px1 - text_cells(number(x1)) - text_cells(x_label) - 10, bottom_margin - 4, number(x1), black);
    text(left + 2, f.py0 + kGlyphHeight, number(y0), black);
    text(left + 2, f.py1, number(y1), black);
    return f;
  };
  // Legends sit in a corner the series leave free: top left, or bottom right.
  auto legend = [&](const Frame& f, int row, const std::string& label, std::array<uint8_t, 3> c, bool bottom_right) {
    const int y = bottom_right ? f.py0 + 8 + (1 - row) * (kGlyphHeight + 5) + kGlyphHeight : f.py1 - 4 - row * (kGlyphHeight + 5);
    const int x = bottom_right ? f.px1 - text_cells(label) : f.px0 + 24;
    canvas.marker(x - 12, y - kGlyphHeight / 2, c);
    text(x, y, label, c);
  };
  auto series = [&](const Frame& f, const std::vector<double>& v, double first, std::array<uint8_t, 3> c) {
    for (size_t i = 0; i < v.size(); ++i) {
      canvas.marker(f.x(first + double(i)), f.y(v[i]), c);
      if (i > 0) canvas.line(f.x(first + double(i - 1)), f.y(v[i - 1]), f.x(first + double(i)), f.y(v[i]), c);
    }
  };
  // Left: ln(A_i / A_first) and ln(P_i / P_first) against the level.
  std::vector<double> la, lp;
  for (size_t i = 0; i < measures.area.size(); ++i) {
    la.push_back(std::log(measures.area[i] / measures.area[0]));
    lp.push_back(std::log(measures.perimeter[i] / measures.perimeter[0]));
  }
  double lo = 0, hi = 0;
  for (double v : la) lo = std::min(lo, v), hi = std::max(hi, v);
  for (double v : lp) lo = std::min(lo, v), hi = std::max(hi, v);
  const double first = measures.first_level;
  const std::string& a = labels.first_symbol;
  const std::string& p = labels.second_symbol;
  const Frame left = make_frame(first, first + std::max(1.0, double(la.size()) - 1), lo, hi, 0,
                                labels.first + ", " + labels.second, "LEVEL I",
                                "LN(" + a + "_I/" + a + "_0), LN(" + p + "_I/" + p + "_0)");
  series(left, la, first, red);
  series(left, lp, first, blue);
  legend(left, 0, labels.first, red, false);
  legend(left, 1, labels.second, blue, false);
  // Middle: ln N against ln(1/eps), and the fitted line through the mean point.
  if (!boxes.log_count.empty()) {
    const auto [xmin, xmax] = std::minmax_element(boxes.log_inverse_size.begin(), boxes.log_inverse_size.end());
    const auto [ymin, ymax] = std::minmax_element(boxes.log_count.begin(), boxes.log_count.end());
    const Frame middle = make_frame(*xmin, *xmax, *ymin, *ymax, 1, "BOX COUNTING", "LN(1/E)", "LN N");
    double mx = 0, my = 0;
    for (size_t i = 0; i < boxes.log_count.size(); ++i) mx += boxes.log_inverse_size[i], my += boxes.log_count[i];
    mx /= double(boxes.log_count.size());
    my /= double(boxes.log_count.size());
    canvas.line(middle.x(*xmin), middle.y(my + boxes.dimension * (*xmin - mx)), middle.x(*xmax),
                middle.y(my + boxes.dimension * (*xmax - mx)), green);
    for (size_t i = 0; i < boxes.log_count.size(); ++i)
      canvas.marker(middle.x(boxes.log_inverse_size[i]), middle.y(boxes.log_count[i]), black);
    legend(middle, 0, "BOXES", black, false);
    legend(middle, 1, "D = " + number(boxes.dimension), green, false);
  }
  // Right: R_i = N^L_i / (N^C_i + N^L_i) against the level, and its limit.
  if (!ratio.empty()) {
    double rhi = ratio_limit;
    for (double v : ratio) rhi = std::max(rhi, v);
    const Frame right = make_frame(0, std::max(1.0, double(ratio.size()) - 1), 0, rhi * 1.1 + 1e-12, 2, "LACUNARITY",
                                   "LEVEL I", "R_I");
    for (int x = right.px0; x < right.px1; x += 6) canvas.line(x, right.y(ratio_limit), x + 3, right.y(ratio_limit), grey);
    series(right, ratio, 0, purple);
    legend(right, 0, "R_I", purple, true);
    legend(right, 1, "R = " + number(ratio_limit), grey, true);
  }
  return canvas.rgb;
}

}  // namespace bcifs
}  // namespace lacuna
