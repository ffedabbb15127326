#include "bcifs/volume.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "errors.h"

namespace lacuna {
namespace bcifs {
namespace {

std::string cell_name(int cell, int face) { return "cell " + std::to_string(cell) + " face " + std::to_string(face); }

// Newell's vector: twice the polygon's vector area.
Vec3d newell(const std::vector<Vec3d>& p) {
  Vec3d n{0, 0, 0};
  for (size_t i = 0; i < p.size(); ++i) n += cross(p[i], p[(i + 1) % p.size()]);
  return n;
}

std::vector<Vec3d> face_points(const Polyhedron& shape, int face) {
  std::vector<Vec3d> out;
  for (int c : shape.faces[size_t(face)]) out.push_back(shape.corners_mm[size_t(c)]);
  return out;
}

template <class T>
std::vector<T> rotated(const std::vector<T>& v, int shift) {
  std::vector<T> out(v.size());
  for (size_t j = 0; j < v.size(); ++j) out[j] = v[(j + size_t(shift)) % v.size()];
  return out;
}

// A delay raised to at least d.
FaceType delayed(FaceType f, int d) {
  f.delay = std::max(f.delay, d);
  return f;
}

FaceType quad_type(const EdgeType& x, const InteriorFaces& interior) {
  return FaceType{{x, interior.radial, x, interior.radial}, interior.edges, interior.algorithm, 1};
}

bool lex_less(const Vec3d& a, const Vec3d& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

struct PolygonKey {
  std::vector<Vec3d> sorted;
  bool operator<(const PolygonKey& o) const {
    return std::lexicographical_compare(sorted.begin(), sorted.end(), o.sorted.begin(), o.sorted.end(), lex_less);
  }
};

PolygonKey key_of(const std::vector<Vec3d>& polygon) {
  PolygonKey k{polygon};
  std::sort(k.sorted.begin(), k.sorted.end(), lex_less);
  return k;
}

// Where each root face's object is: cells sharing a face point at one object (the first cell's polygon).
struct RootFaces {
  std::vector<std::vector<int>> object;  // per cell, per face
  std::vector<std::pair<int, int>> owner;  // per object: (cell, face) whose polygon and type it has
  std::vector<int> delay;                  // per object: the largest delay of the cells that have it
};

RootFaces root_faces(const VolumeSpec& spec, const std::vector<SharedFace>& shared) {
  RootFaces r;
  r.object.resize(spec.cells.size());
  for (size_t c = 0; c < spec.cells.size(); ++c) r.object[c].assign(spec.cells[c].shape.faces.size(), -1);
  std::map<std::pair<int, int>, std::pair<int, int>> partner;
  for (const SharedFace& s : shared) partner[{s.cell_b, s.face_b}] = {s.cell_a, s.face_a};
  for (size_t c = 0; c < spec.cells.size(); ++c)
    for (size_t f = 0; f < spec.cells[c].shape.faces.size(); ++f) {
      const auto found = partner.find({int(c), int(f)});
      if (found != partner.end()) {
        const int o = r.object[size_t(found->second.first)][size_t(found->second.second)];
        r.object[c][f] = o;
        r.delay[size_t(o)] = std::max(r.delay[size_t(o)], spec.cells[c].delay);
        continue;
      }
      r.object[c][f] = int(r.owner.size());
      r.owner.push_back({int(c), int(f)});
      r.delay.push_back(spec.cells[c].delay);
    }
  return r;
}

// The face type of a root face object (delay raised), or none for a plain face.
bool root_face_type(const VolumeSpec& spec, const RootFaces& r, int object, FaceType& type) {
  const auto [c, f] = r.owner[size_t(object)];
  const CellSpec& cell = spec.cells[size_t(c)];
  if (cell.plain[size_t(f)]) return false;
  type = delayed(cell.face_types[size_t(f)], r.delay[size_t(object)]);
  return true;
}

Vec3d corner_average(const std::vector<Vec3d>& points) {
  Vec3d sum{0, 0, 0};
  for (const Vec3d& p : points) sum += p;
  return sum / double(points.size());
}

}  // namespace

void set_uniform_faces(CellSpec& cell, const FaceType& face, bool plain) {
  cell.face_types.clear();
  cell.plain.clear();
  for (const auto& loop : cell.shape.faces) {
    FaceType t = face;
    t.boundary.assign(loop.size(), face.boundary.at(0));
    cell.face_types.push_back(t);
    cell.plain.push_back(plain ? 1 : 0);
  }
}

Polyhedron regular_cell(CellKind shape, double edge_mm, const Vec3d& center_mm) {
  Polyhedron p;
  std::map<PolygonKey, int> index;
  for (const std::vector<Vec3d>& face : cell_faces(shape, edge_mm)) {
    std::vector<int> loop;
    for (const Vec3d& q : face) {
      const auto [it, added] = index.emplace(PolygonKey{{q}}, int(p.corners_mm.size()));
      if (added) p.corners_mm.push_back(q);
      loop.push_back(it->second);
    }
    p.faces.push_back(std::move(loop));
  }
  for (Vec3d& q : p.corners_mm) q = q + center_mm;
  return p;
}

std::vector<SharedFace> shared_faces(const VolumeSpec& spec) {
  if (spec.cells.empty()) throw InvalidInput("a lacunar volume needs at least one cell");
  std::map<PolygonKey, std::pair<int, int>> seen;
  std::vector<SharedFace> shared;
  std::set<std::pair<int, int>> taken;
  for (size_t c = 0; c < spec.cells.size(); ++c) {
    const CellSpec& cell = spec.cells[c];
    const Polyhedron& shape = cell.shape;
    const std::string cn = "cell " + std::to_string(c);
    if (shape.faces.size() < 4) throw InvalidInput(cn + ": a cell needs at least 4 faces");
    if (cell.face_types.size() != shape.faces.size() || cell.plain.size() != shape.faces.size())
      throw InvalidInput(cn + ": expected one face type per face");
    if (cell.delay < 1) throw InvalidInput(cn + ": the delay must be at least 1");
    double size = 0;
    for (const Vec3d& p : shape.corners_mm) {
      if (!is_finite(p)) throw InvalidInput(cn + ": a corner is not finite");
      size = std::max(size, norm(p - shape.corners_mm[0]));
    }
    // Every edge of the cell is in two faces that agree on its type.
    std::map<std::pair<int, int>, std::pair<int, int>> edges;  // (from, to) -> (face, edge)
    for (size_t f = 0; f < shape.faces.size(); ++f) {
      const std::vector<int>& loop = shape.faces[f];
      const std::string fn = cell_name(int(c), int(f));
      if (loop.size() < 3) throw InvalidInput(fn + ": a face needs at least 3 corners");
      for (int k : loop)
        if (k < 0 || k >= int(shape.corners_mm.size())) throw InvalidInput(fn + ": corner index out of range");
      if (!cell.plain[f]) {
        try {
          validate(cell.face_types[f]);
        } catch (const InvalidInput& e) {
          throw InvalidInput(fn + ": " + e.what());
        }
        if (cell.face_types[f].boundary.size() != loop.size())
          throw InvalidInput(fn + ": its type " + to_string(cell.face_types[f]) + " has " +
                             std::to_string(cell.face_types[f].boundary.size()) + " edges but the face has " +
                             std::to_string(loop.size()) + " sides");
      }
      const std::vector<Vec3d> pts = face_points(shape, int(f));
      const Vec3d n = newell(pts);
      if (!(norm(n) > 0)) throw InvalidInput(fn + ": the face has no area");
      const Vec3d u = n / norm(n);
      for (const Vec3d& p : pts)
        if (std::fabs(dot(p - pts[0], u)) > 1e-9 * (1 + size))
          throw InvalidInput(fn + ": the face is not planar");
      for (size_t j = 0; j < loop.size(); ++j) {
        const int a = loop[j], b = loop[(j + 1) % loop.size()];
        if (!edges.emplace(std::make_pair(a, b), std::make_pair(int(f), int(j))).second)
          throw InvalidInput(fn + ": edge " + std::to_string(j) + " is walked the same way by two faces");
      }
    }
    for (const auto& [ab, fe] : edges) {
      const auto other = edges.find({ab.second, ab.first});
      if (other == edges.end())
        throw InvalidInput(cell_name(int(c), fe.first) + ": edge " + std::to_string(fe.second) +
                           " is in no other face: the cell is not closed");
      const int f = fe.first, g = other->second.first;
      if (cell.plain[size_t(f)] || cell.plain[size_t(g)]) continue;
      const EdgeType& x = cell.face_types[size_t(f)].boundary[size_t(fe.second)];
      const EdgeType& y = cell.face_types[size_t(g)].boundary[size_t(other->second.second)];
      if (x != y)
        throw InvalidInput(cell_name(int(c), f) + " edge " + std::to_string(fe.second) + " is " + to_string(x) +
                           " but the same edge of face " + std::to_string(g) + " is " + to_string(y));
    }
    double volume = 0;
    for (size_t f = 0; f < shape.faces.size(); ++f) {
      const std::vector<Vec3d> pts = face_points(shape, int(f));
      for (size_t j = 1; j + 1 < pts.size(); ++j)
        volume += dot(pts[0] - shape.corners_mm[0], cross(pts[j] - shape.corners_mm[0], pts[j + 1] - shape.corners_mm[0]));
    }
    if (!(volume > 0)) throw InvalidInput(cn + ": its faces must run counter-clockwise seen from outside");
    // Convex: every corner on the inner side of every face's plane (the rasterizer takes cells as convex, and the
    // lacuna about the corners' average must stay inside).
    for (size_t f = 0; f < shape.faces.size(); ++f) {
      const std::vector<Vec3d> pts = face_points(shape, int(f));
      const Vec3d n = newell(pts);
      const Vec3d u = n / norm(n);
      for (const Vec3d& p : shape.corners_mm)
        if (dot(p - pts[0], u) > 1e-9 * (1 + size))
          throw InvalidInput(cell_name(int(c), int(f)) + ": a corner lies outside the face's plane: the cell is not convex");
    }
    // Faces shared with earlier cells.
    for (size_t f = 0; f < shape.faces.size(); ++f) {
      const std::vector<Vec3d> pts = face_points(shape, int(f));
      const auto [it, added] = seen.emplace(key_of(pts), std::make_pair(int(c), int(f)));
      if (added) continue;
      const auto [oc, of] = it->second;
      const std::string both = cell_name(oc, of) + " and " + cell_name(int(c), int(f));
      if (oc == int(c)) throw InvalidInput(both + " have the same corners");
      if (!taken.insert({oc, of}).second) throw InvalidInput(both + ": a face is shared by more than two cells");
      // The same corners in reverse order: the shift that lines them up.
      const std::vector<Vec3d> first = face_points(spec.cells[size_t(oc)].shape, of);
      const size_t n = pts.size();
      int match = -1;
      for (size_t s = 0; s < n && match < 0; ++s) {
        bool ok = true;
        for (size_t j = 0; j < n && ok; ++j) ok = first[j] == pts[(s + n - j) % n];
        if (ok) match = int(s);
      }
      if (match < 0) throw InvalidInput(both + " have the same corners but not as two sides of one face");
      const CellSpec& other = spec.cells[size_t(oc)];
      if (bool(other.plain[size_t(of)]) != bool(cell.plain[f]))
        throw InvalidInput(both + " share a face that only one of them makes plain");
      if (!cell.plain[f]) {
        // Seen from the other side the boundary is read backwards: edge j of the first is the edge from
        // pts[(s - j)] to pts[(s - j - 1)], which is edge (s - j - 1) of the second.
        std::vector<EdgeType> mine(n);
        const std::vector<EdgeType>& theirs = other.face_types[size_t(of)].boundary;
        for (size_t j = 0; j < n; ++j) mine[j] = cell.face_types[f].boundary[(size_t(match) + 2 * n - j - 1) % n];
        FaceType a = other.face_types[size_t(of)], b = cell.face_types[f];
        if (mine != theirs || !(a.edges == b.edges) || a.algorithm != b.algorithm || a.delay != b.delay)
          throw InvalidInput(both + " share a face but see different types: " + to_string(a) + " against " +
                             to_string(b) + " read backwards");
      }
      shared.push_back(SharedFace{oc, of, int(c), int(f)});
    }
  }
  return shared;
}

VolumeRules build_volume_rules(const VolumeSpec& spec, const VolumeClosureOptions& options) {
  VolumeRules out;
  out.interior = spec.interior;
  if (!spec.interior.plain) {
    validate(FaceType{{spec.interior.radial, spec.interior.radial}, spec.interior.edges, spec.interior.algorithm, 1});
  }
  out.shared = shared_faces(spec);
  const RootFaces roots = root_faces(spec, out.shared);

  // The face types: the root faces, closed, and an interior quad for every edge type that appears, closed again,
  // until no new quad is needed.
  std::vector<FaceType> face_roots;
  for (size_t o = 0; o < roots.owner.size(); ++o) {
    FaceType t;
    if (root_face_type(spec, roots, int(o), t)) face_roots.push_back(t);
  }
  ClosureOptions closure;
  closure.max_types = options.max_face_types;
  // With every face plain no face type is ever needed: plain faces make plain sub-cells.
  while (!face_roots.empty()) {
    out.faces = build_rules(face_roots, closure);
    if (spec.interior.plain) break;
    std::set<EdgeType> edge_types;
    for (const FaceRule& rule : out.faces.rules)
      for (const EdgeType& e : rule.face.boundary) edge_types.insert(e);
    bool added = false;
    for (const EdgeType& e : edge_types) {
      const FaceType q = quad_type(e, spec.interior);
      if (find_type(out.faces, q) < 0) {
        face_roots.push_back(q);
        added = true;
      }
    }
    if (!added) break;
  }

  std::map<EdgeType, int> quad_ids;
  auto quad_id = [&](const EdgeType& x) {
    const auto found = quad_ids.find(x);
    if (found != quad_ids.end()) return found->second;
    const int id = find_type(out.faces, quad_type(x, spec.interior));
    if (id < 0) throw InternalError("lacunar volume: no interior quad for edge " + to_string(x));
    quad_ids[x] = id;
    return id;
  };
  auto frustum = [&](const CellSlot& base) {
    CellType t;
    t.faces = {base, base};
    if (base.type < 0) {
      t.faces.insert(t.faces.end(), size_t(base.sides), CellSlot{-1, 4});
    } else {
      for (const EdgeType& x : out.faces.rules[size_t(base.type)].face.boundary)
        t.faces.push_back(spec.interior.plain ? CellSlot{-1, 4} : CellSlot{quad_id(x), 0});
    }
    std::sort(t.faces.begin(), t.faces.end());
    return t;
  };

  std::map<CellType, int> ids;
  std::vector<CellType> queue;
  auto id_of = [&](const CellType& t) {
    const auto [it, added] = ids.emplace(t, int(queue.size()));
    if (added) {
      if (int(queue.size()) >= options.max_cell_types)
        throw ResourceLimit("lacunar volume: more than " + std::to_string(options.max_cell_types) + " cell types");
      queue.push_back(t);
    }
    return it->second;
  };
  for (size_t c = 0; c < spec.cells.size(); ++c) {
    CellType t;
    t.delay = spec.cells[c].delay;
    for (size_t f = 0; f < spec.cells[c].shape.faces.size(); ++f) {
      FaceType ft;
      const int o = roots.object[c][f];
      if (root_face_type(spec, roots, o, ft))
        t.faces.push_back(CellSlot{find_type(out.faces, ft), 0});
      else
        t.faces.push_back(CellSlot{-1, int(spec.cells[c].shape.faces[f].size())});
      out.root_faces.push_back(t.faces.back().type);
    }
    std::sort(t.faces.begin(), t.faces.end());
    out.roots.push_back(id_of(t));
  }
  for (size_t q = 0; q < queue.size(); ++q) {
    const CellType t = queue[q];
    CellRule rule;
    rule.cell = t;
    if (t.delay >= 2) {
      CellType child;
      child.delay = t.delay - 1;
      for (const CellSlot& s : t.faces) {
        if (s.type < 0) {
          child.faces.push_back(s);
          continue;
        }
        const FaceRule& fr = out.faces.rules[size_t(s.type)];
        if (fr.subfaces.size() != 1)
          throw InternalError("lacunar volume: a delayed cell's face " + to_string(fr.face) + " is not delayed");
        child.faces.push_back(CellSlot{fr.subfaces[0].type, 0});
      }
      std::sort(child.faces.begin(), child.faces.end());
      rule.children.push_back(id_of(child));
    } else {
      rule.lacunas = 1;
      for (const CellSlot& s : t.faces) {
        if (s.type < 0) {
          rule.children.push_back(id_of(frustum(s)));
          continue;
        }
        for (const SubFace& sub : out.faces.rules[size_t(s.type)].subfaces)
          rule.children.push_back(id_of(frustum(CellSlot{sub.type, 0})));
      }
    }
    out.cells.push_back(std::move(rule));
  }
  return out;
}

Lacunarity volume_lacunarity(const VolumeRules& rules, int type, int levels) {
  if (type < 0 || type >= int(rules.cells.size()))
    throw InvalidInput("volume_lacunarity: cell type " + std::to_string(type) + " is not in the rules");
  std::vector<int> local(rules.cells.size(), -1), reach{type};
  local[size_t(type)] = 0;
  for (size_t q = 0; q < reach.size(); ++q)
    for (int child : rules.cells[size_t(reach[q])].children)
      if (local[size_t(child)] < 0) {
        local[size_t(child)] = int(reach.size());
        reach.push_back(child);
      }
  const Eigen::Index count = Eigen::Index(reach.size());
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(count, count);
  Eigen::VectorXd l(count);
  for (Eigen::Index t = 0; t < count; ++t) {
    const CellRule& rule = rules.cells[size_t(reach[size_t(t)])];
    l(t) = rule.lacunas;
    for (int child : rule.children) s(t, local[size_t(child)]) += 1;
  }
  return lacunarity(s, l, levels);
}

double volume_cells(const VolumeRules& rules, int level) {
  // Counts per type at `level`, from the leaves up: n_level(t) = 1, n_i(t) = sum over children of n_(i+1).
  std::vector<double> n(rules.cells.size(), 1.0);
  for (int i = 0; i < level; ++i) {
    std::vector<double> next(rules.cells.size(), 0.0);
    for (size_t t = 0; t < rules.cells.size(); ++t)
      for (int child : rules.cells[t].children) next[t] += n[size_t(child)];
    n.swap(next);
  }
  double total = 0;
  for (int r : rules.roots) total += n[size_t(r)];
  return total;
}

double volume_lacunas(const VolumeRules& rules, int level) {
  // L_0(t) = 0, L_i(t) = l(t) + sum over children of L_(i-1).
  std::vector<double> l(rules.cells.size(), 0.0);
  for (int i = 0; i < level; ++i) {
    std::vector<double> next(rules.cells.size(), 0.0);
    for (size_t t = 0; t < rules.cells.size(); ++t) {
      next[t] = rules.cells[t].lacunas;
      for (int child : rules.cells[t].children) next[t] += l[size_t(child)];
    }
    l.swap(next);
  }
  double total = 0;
  for (int r : rules.roots) total += l[size_t(r)];
  return total;
}

void validate(const VolumeGeometryOptions& options) {
  if (!(options.lacuna_scale > 0 && options.lacuna_scale < 1))
    throw InvalidInput("the cells' lacuna_scale must be in (0, 1), got " + std::to_string(options.lacuna_scale));
  for (double size : options.last_lacuna_mm)
    if (!(size >= 0 && std::isfinite(size)))
      throw InvalidInput("a cell's last lacuna size must be >= 0 mm, got " + std::to_string(size));
  validate(options.faces);
}

namespace {

// Builds one level from the previous.
class Realizer {
 public:
  Realizer(const VolumeRules& rules, const VolumeSpec& spec, const VolumeGeometryOptions& options)
      : rules_(rules), spec_(spec), options_(options) {
    if (!options.last_lacuna_mm.empty() && options.last_lacuna_mm.size() != spec.cells.size())
      throw InvalidInput("lacunar volume: " + std::to_string(options.last_lacuna_mm.size()) +
                         " last lacuna sizes for " + std::to_string(spec.cells.size()) + " cells");
    for (size_t t = 0; t < rules.cells.size(); ++t) ids_[rules.cells[t].cell] = int(t);
  }

  VolumeLevel first() {
    VolumeLevel out;
    const RootFaces roots = root_faces(spec_, rules_.shared);
    for (size_t o = 0; o < roots.owner.size(); ++o) {
      const auto [c, f] = roots.owner[o];
      std::vector<Vec3d> polygon = face_points(spec_.cells[size_t(c)].shape, f);
      FaceType t;
      int type = -1;
      if (root_face_type(spec_, roots, int(o), t)) {
        type = find_type(rules_.faces, t);
        polygon = rotated(polygon, canonical_shift(t.boundary));
      }
      out.faces.push_back(VolumeFace{std::move(polygon), type});
      out.owners.push_back(0);
    }
    for (size_t c = 0; c < spec_.cells.size(); ++c) {
      VolumeCell cell;
      cell.type = rules_.roots[c];
      cell.delay = spec_.cells[c].delay;
      cell.root = int(c);
      cell.origin = int(c);
      cell.faces = roots.object[c];
      for (int f : cell.faces) ++out.owners[size_t(f)];
      cell.apex = corner_average(spec_.cells[c].shape.corners_mm);
      out.cells.push_back(std::move(cell));
    }
    return out;
  }

  // `last`: the realization's last subdivision, where the cells' last lacuna scales apply.
  VolumeLevel next(const VolumeLevel& level, bool last) {
    VolumeLevel out;
    out.level = level.level + 1;
    keys_.clear();
    const bool own_sizes = last && !options_.last_lacuna_mm.empty();
    for (const VolumeCell& cell : level.cells) {
      const double s = own_sizes && cell.delay < 2 ? last_scale(options_.last_lacuna_mm[size_t(cell.origin)],
                                                                cell_volume(cell, spec_), options_.lacuna_scale)
                                                   : options_.lacuna_scale;
      if (cell.delay >= 2) {
        VolumeCell child = cell;
        child.delay = cell.delay - 1;
        child.faces.clear();
        for (int f : cell.faces) {
          const VolumeFace& face = level.faces[size_t(f)];
          if (face.type < 0) {
            child.faces.push_back(add(out, face.polygon, -1));
            continue;
          }
          const std::vector<VolumeFace> subs = sub_faces(face);
          if (subs.size() != 1) throw InternalError("lacunar volume: a delayed cell's face has several sub-faces");
          child.faces.push_back(add(out, subs[0].polygon, subs[0].type));
        }
        child.type = type_of(out, child);
        out.cells.push_back(std::move(child));
        continue;
      }
      const Vec3d c = cell.apex;
      for (int f : cell.faces) {
        const VolumeFace& face = level.faces[size_t(f)];
        const std::vector<VolumeFace> subs = face.type < 0 ? std::vector<VolumeFace>{face} : sub_faces(face);
        for (const VolumeFace& g : subs) {
          const size_t n = g.polygon.size();
          std::vector<Vec3d> inner(n);
          for (size_t j = 0; j < n; ++j) inner[j] = c * (1 - s) + g.polygon[j] * s;
          VolumeCell child;
          child.faces.push_back(add(out, g.polygon, g.type));
          child.faces.push_back(add(out, inner, g.type));
          for (size_t j = 0; j < n; ++j) {
            std::vector<Vec3d> quad{g.polygon[j], g.polygon[(j + 1) % n], inner[(j + 1) % n], inner[j]};
            if (g.type < 0 || rules_.interior.plain) {
              child.faces.push_back(add(out, quad, -1));
              continue;
            }
            const auto [qt, shift] = quad_of(rules_.faces.rules[size_t(g.type)].face.boundary[j]);
            child.faces.push_back(add(out, rotated(quad, shift), qt));
          }
          child.origin = cell.origin;
          child.base = g.polygon;
          child.base_apex = c;
          child.base_scale = s;
          std::vector<Vec3d> corners = g.polygon;
          corners.insert(corners.end(), inner.begin(), inner.end());
          child.apex = corner_average(corners);
          child.type = type_of(out, child);
          out.cells.push_back(std::move(child));
        }
      }
    }
    return out;
  }

 private:
  // The sub-faces of a face by its rule, each coordinate realized as a planar control polygon (the rule's points
  // are affine combinations of the control points, so this is the rule applied in the face's own plane).
  std::vector<VolumeFace> sub_faces(const VolumeFace& face) const {
    const FaceRule& rule = rules_.faces.rules[size_t(face.type)];
    std::vector<Vec2d> xy, z0;
    for (const Vec3d& p : face.polygon) {
      xy.push_back({p.x, p.y});
      z0.push_back({p.z, 0});
    }
    const auto a = subface_polygons(rule, xy, options_.faces);
    const auto b = subface_polygons(rule, z0, options_.faces);
    std::vector<VolumeFace> out;
    for (size_t k = 0; k < a.size(); ++k) {
      std::vector<Vec3d> written;
      for (size_t j = 0; j < a[k].size(); ++j) written.push_back({a[k][j].x, a[k][j].y, b[k][j].x});
      out.push_back(VolumeFace{rotated(written, rule.subfaces[k].shift), rule.subfaces[k].type});
    }
    return out;
  }

  // The interior quad over an edge of type x: its face-type id and canonical shift.
  std::pair<int, int> quad_of(const EdgeType& x) {
    const auto found = quads_.find(x);
    if (found != quads_.end()) return found->second;
    const FaceType q = quad_type(x, rules_.interior);
    const int id = find_type(rules_.faces, q);
    if (id < 0) throw InternalError("lacunar volume: no interior quad for edge " + to_string(x));
    return quads_[x] = {id, canonical_shift(q.boundary)};
  }

  int add(VolumeLevel& level, const std::vector<Vec3d>& polygon, int type) {
    const auto [it, added] = keys_.emplace(key_of(polygon), int(level.faces.size()));
    if (added) {
      level.faces.push_back(VolumeFace{polygon, type});
      level.owners.push_back(1);
    } else {
      if (level.faces[size_t(it->second)].type != type)
        throw InternalError("lacunar volume: two cells see one face with different types");
      ++level.owners[size_t(it->second)];
    }
    return it->second;
  }

  int type_of(const VolumeLevel& level, const VolumeCell& cell) const {
    CellType t;
    t.delay = cell.delay;
    for (int f : cell.faces) {
      const VolumeFace& face = level.faces[size_t(f)];
      t.faces.push_back(CellSlot{face.type, face.type < 0 ? int(face.polygon.size()) : 0});
    }
    std::sort(t.faces.begin(), t.faces.end());
    const auto found = ids_.find(t);
    if (found == ids_.end()) throw InternalError("lacunar volume: a realized cell has no rule");
    return found->second;
  }

  const VolumeRules& rules_;
  const VolumeSpec& spec_;
  const VolumeGeometryOptions& options_;
  std::map<CellType, int> ids_;
  std::map<PolygonKey, int> keys_;
  std::map<EdgeType, std::pair<int, int>> quads_;
};

// Cell counts never fall from one level to the next (every cell has a sub-cell): the last level decides.
void check_cell_count(const VolumeRules& rules, int levels) {
  const double cells = volume_cells(rules, levels);
  if (cells > kMaxVolumeCells)
    throw ResourceLimit("level " + std::to_string(levels) + " of the lacunar volume has " + message_number(cells) +
                        " cells, more than " + message_number(kMaxVolumeCells) + "; use a lower level");
}

}  // namespace

VolumeLevel realize_volume(const VolumeRules& rules, const VolumeSpec& spec, int levels,
                           const VolumeGeometryOptions& options) {
  validate(options);
  if (levels < 0) throw InvalidInput("realize_volume: levels must be >= 0, got " + std::to_string(levels));
  check_cell_count(rules, levels);
  Realizer realizer(rules, spec, options);
  VolumeLevel level = realizer.first();
  for (int i = 0; i < levels; ++i) level = realizer.next(level, i + 1 == levels);
  return level;
}

double cell_volume(const VolumeCell& cell, const VolumeSpec& spec) {
  if (cell.root >= 0) {
    const Polyhedron& p = spec.cells[size_t(cell.root)].shape;
    double v = 0;
    for (size_t f = 0; f < p.faces.size(); ++f) {
      const std::vector<Vec3d> pts = face_points(p, int(f));
      for (size_t j = 1; j + 1 < pts.size(); ++j) v += dot(pts[0], cross(pts[j], pts[j + 1]));
    }
    return v / 6;
  }
  const Vec3d area = newell(cell.base) * 0.5;
  const double pyramid = std::fabs(dot(area, cell.base[0] - cell.base_apex)) / 3;
  const double s = cell.base_scale;
  return pyramid * (1 - s * s * s);
}

namespace {

// Ear clipping of a simple planar polygon (in its own plane): triangles as index triples.
std::vector<std::array<size_t, 3>> ear_clip(const std::vector<Vec3d>& polygon) {
  const Vec3d n = newell(polygon);
  // Drop the axis the normal is largest along; orient so the polygon is counter-clockwise in 2D.
  const int axis = dominant_axis(n);
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double sign = n[axis] >= 0 ? 1 : -1;
  std::vector<Vec2d> p;
  for (const Vec3d& q : polygon) p.push_back({q[u], sign * q[v]});
  std::vector<size_t> left(polygon.size());
  for (size_t i = 0; i < left.size(); ++i) left[i] = i;
  std::vector<std::array<size_t, 3>> out;
  while (left.size() > 3) {
    bool clipped = false;
    for (size_t i = 0; i < left.size() && !clipped; ++i) {
      const size_t a = left[(i + left.size() - 1) % left.size()], b = left[i], c = left[(i + 1) % left.size()];
      if (cross2(p[b] - p[a], p[c] - p[b]) <= 0) continue;  // reflex or flat
      bool empty = true;
      for (size_t k : left) {
        if (k == a || k == b || k == c) continue;
        if (cross2(p[b] - p[a], p[k] - p[a]) >= 0 && cross2(p[c] - p[b], p[k] - p[b]) >= 0 &&
            cross2(p[a] - p[c], p[k] - p[c]) >= 0) {
          empty = false;
          break;
        }
      }
      if (!empty) continue;
      out.push_back({a, b, c});
      left.erase(left.begin() + std::ptrdiff_t(i));
      clipped = true;
    }
    if (!clipped) {
      // Only flat corners left (collinear points): a fan covers what remains.
      for (size_t i = 1; i + 1 < left.size(); ++i) out.push_back({left[0], left[i], left[i + 1]});
      return out;
    }
  }
  out.push_back({left[0], left[1], left[2]});
  return out;
}

bool is_convex(const std::vector<Vec3d>& polygon) {
  const Vec3d n = newell(polygon);
  const size_t m = polygon.size();
  for (size_t i = 0; i < m; ++i) {
    const Vec3d a = polygon[(i + 1) % m] - polygon[i], b = polygon[(i + 2) % m] - polygon[(i + 1) % m];
    if (dot(cross(a, b), n) < -1e-12 * norm(a) * norm(b) * norm(n)) return false;
  }
  return true;
}

void add_frustum(std::map<int, ConvexCells>& groups, const std::vector<Vec3d>& base, const Vec3d& apex, double s) {
  const size_t n = base.size();
  ConvexCells& g = groups[int(2 * n)];
  if (g.faces.empty()) {
    g.corners_per_cell = int(2 * n);
    std::vector<int> outer, inner;
    for (size_t j = 0; j < n; ++j) {
      outer.push_back(int(j));
      inner.push_back(int(n + j));
      g.faces.push_back({int(j), int((j + 1) % n), int(n + (j + 1) % n), int(n + j)});
    }
    g.faces.push_back(outer);
    g.faces.push_back(inner);
  }
  for (const Vec3d& p : base) g.corners_mm.push_back(p);
  for (const Vec3d& p : base) g.corners_mm.push_back(apex * (1 - s) + p * s);
}

}  // namespace

std::vector<ConvexCells> convex_pieces(const VolumeLevel& level, const VolumeSpec& spec) {
  std::map<int, ConvexCells> frusta;
  std::vector<ConvexCells> out;
  for (const VolumeCell& cell : level.cells) {
    if (cell.root >= 0) {
      const Polyhedron& p = spec.cells[size_t(cell.root)].shape;
      ConvexCells c;
      c.corners_per_cell = int(p.corners_mm.size());
      c.faces = p.faces;
      c.corners_mm = p.corners_mm;
      out.push_back(std::move(c));
      continue;
    }
    if (is_convex(cell.base)) {
      add_frustum(frusta, cell.base, cell.base_apex, cell.base_scale);
      continue;
    }
    for (const auto& t : ear_clip(cell.base))
      add_frustum(frusta, {cell.base[t[0]], cell.base[t[1]], cell.base[t[2]]}, cell.base_apex, cell.base_scale);
  }
  for (auto& [corners, cells] : frusta) out.push_back(std::move(cells));
  // Cells that share a face meet exactly, so their union's distance is 0 on the face; where the face lies on a
  // voxel plane the samples there would read "outside" and the solid would crack along it. Each piece grows by a
  // hair (a relative 1e-9 about its corners' average: 1e-8 mm on a 10 mm cell, far below any voxel and far above
  // the rounding of a plane's offset), so shared faces are overlaps instead.
  for (ConvexCells& cells : out) {
    const size_t m = size_t(cells.corners_per_cell);
    for (size_t k = 0; k < cells.size(); ++k) {
      Vec3d* p = cells.corners_mm.data() + k * m;
      Vec3d c{0, 0, 0};
      for (size_t i = 0; i < m; ++i) c += p[i];
      c = c / double(m);
      for (size_t i = 0; i < m; ++i) p[i] = c + (p[i] - c) * (1 + 1e-9);
    }
  }
  return out;
}

double level_shrink(const VolumeSpec& spec, int cell, const VolumeGeometryOptions& options) {
  if (cell < 0 || cell >= int(spec.cells.size())) throw InvalidInput("level_shrink: no such cell");
  VolumeSpec alone;
  alone.interior = spec.interior;
  alone.cells.push_back(spec.cells[size_t(cell)]);
  alone.cells[0].delay = 1;
  const VolumeRules rules = build_volume_rules(alone);
  VolumeGeometryOptions common = options;
  common.last_lacuna_mm.clear();
  auto mean_size = [&](int level) {
    const VolumeLevel l = realize_volume(rules, alone, level, common);
    double sum = 0;
    for (const VolumeCell& c : l.cells) sum += std::log(std::cbrt(cell_volume(c, alone)));
    return std::exp(sum / double(l.cells.size()));
  };
  return mean_size(1) / mean_size(2);
}

std::vector<int> delays_for_sizes(const std::vector<double>& sizes_mm, int level, double shrink) {
  if (level < 1) throw InvalidInput("delays_for_sizes: level must be >= 1");
  if (!(shrink > 1 && std::isfinite(shrink))) throw InvalidInput("delays_for_sizes: the shrink must be > 1");
  std::vector<int> delays;
  if (sizes_mm.empty()) return delays;
  for (double l : sizes_mm)
    if (!(l > 0 && std::isfinite(l))) throw InvalidInput("delays_for_sizes: every size must be positive");
  std::vector<double> sorted = sizes_mm;
  std::sort(sorted.begin(), sorted.end());
  const double reference = sorted[std::min(sorted.size() - 1, size_t(0.9 * double(sorted.size())))];
  for (double l : sizes_mm) {
    const double wait = std::round(std::log(reference / l) / std::log(shrink));
    delays.push_back(int(std::clamp(1.0 + std::max(wait, 0.0), 1.0, double(level))));
  }
  return delays;
}

double last_scale(double size_mm, double volume_mm3, double lacuna_scale) {
  if (!(size_mm > 0) || !(volume_mm3 > 0)) return lacuna_scale;
  return std::clamp(size_mm / std::cbrt(volume_mm3), lacuna_scale / 3, lacuna_scale);
}

LastLacunas last_lacuna_sizes(const VolumeRules& rules, const VolumeSpec& spec, int level,
                              const VolumeGeometryOptions& options) {
  if (level < 1) throw InvalidInput("last_lacuna_sizes: level must be >= 1");
  const size_t n = spec.cells.size();
  if (!options.last_lacuna_mm.empty() && options.last_lacuna_mm.size() != n)
    throw InvalidInput("last_lacuna_sizes: one last lacuna size per cell expected");
  VolumeGeometryOptions before_options = options;  // the last sizes belong to the subdivision after `before`
  before_options.last_lacuna_mm.clear();
  const VolumeLevel before = realize_volume(rules, spec, level - 1, before_options);
  std::vector<double> log_sum(n, 0.0), count(n, 0.0);
  LastLacunas out;
  out.smallest_mm.assign(n, HUGE_VAL);
  out.largest_mm.assign(n, 0.0);
  out.min_scale = HUGE_VAL;
  for (const VolumeCell& cell : before.cells) {
    if (cell.delay != 1) continue;
    const size_t c = size_t(cell.origin);
    const double volume = cell_volume(cell, spec);
    const double s = options.last_lacuna_mm.empty() ? options.lacuna_scale
                                                     : last_scale(options.last_lacuna_mm[c], volume, options.lacuna_scale);
    const double size = s * std::cbrt(volume);
    log_sum[c] += std::log(size);
    count[c] += 1;
    out.smallest_mm[c] = std::min(out.smallest_mm[c], size);
    out.largest_mm[c] = std::max(out.largest_mm[c], size);
    out.min_scale = std::min(out.min_scale, s);
    out.max_scale = std::max(out.max_scale, s);
  }
  for (size_t c = 0; c < n; ++c) {
    out.mean_mm.push_back(count[c] > 0 ? std::exp(log_sum[c] / count[c]) : 0.0);
    if (!(count[c] > 0)) out.smallest_mm[c] = 0;
  }
  if (!(out.max_scale > 0)) out.min_scale = 0;
  return out;
}

VolumeMeasures volume_measures(const VolumeRules& rules, const VolumeSpec& spec, int levels,
                               const VolumeGeometryOptions& options, VolumeLevel* last) {
  validate(options);
  if (levels < 0) throw InvalidInput("volume_measures: levels must be >= 0, got " + std::to_string(levels));
  check_cell_count(rules, levels);
  VolumeMeasures m;
  Realizer realizer(rules, spec, options);
  VolumeLevel level = realizer.first();
  double tunnels = 0, lacunas = 0, opened = 0;
  for (int i = 0;; ++i) {
    m.tunnels.push_back(opened);
    m.lacunas.push_back(lacunas);
    m.genus.push_back(tunnels - lacunas);
    double v = 0, a = 0;
    for (const VolumeCell& cell : level.cells) v += cell_volume(cell, spec);
    for (size_t f = 0; f < level.faces.size(); ++f)
      if (level.owners[f] == 1) a += norm(newell(level.faces[f].polygon)) / 2;
    m.volume.push_back(v);
    m.surface.push_back(a);
    if (i == levels) {
      if (last) *last = std::move(level);
      break;
    }
    // What the next subdivision opens and empties. A delayed cell's faces are delayed too, so a face of delay 1
    // belongs to cells that all subdivide now.
    opened = 0;
    for (const VolumeFace& face : level.faces)
      if (face.type >= 0 && rules.faces.rules[size_t(face.type)].face.delay == 1) opened += 1;
    for (const VolumeCell& cell : level.cells) lacunas += cell.delay == 1;
    tunnels += opened;
    level = realizer.next(level, i + 1 == levels);
  }
  if (levels > 0) {
    m.volume_factor = std::pow(m.volume.back() / m.volume.front(), 1.0 / levels);
    m.surface_factor = std::pow(m.surface.back() / m.surface.front(), 1.0 / levels);
  }
  return m;
}

}  // namespace bcifs
}  // namespace lacuna
