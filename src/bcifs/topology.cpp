#include "bcifs/topology.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <unordered_map>
#include <string>
#include <utility>

#include "errors.h"

namespace lacuna {
namespace bcifs {
namespace {

constexpr int kMaxEdgeCount = 1000000;  // n and d beyond this are surely typos (and overflow n^levels)

std::vector<std::string> split_tokens(const std::string& text) {
  // Brackets are decoration: < > and the UTF-8 angle brackets U+27E8, U+27E9, and ( ).
  std::string cleaned = text;
  for (const std::string bracket : {"\xE2\x9F\xA8", "\xE2\x9F\xA9"}) {
    for (size_t at = cleaned.find(bracket); at != std::string::npos; at = cleaned.find(bracket))
      cleaned.replace(at, bracket.size(), " ");
  }
  std::vector<std::string> tokens;
  std::string current;
  for (char c : cleaned) {
    if (c == ' ' || c == ',' || c == '\t' || c == '\n' || c == '\r' || c == '<' || c == '>' || c == '(' ||
        c == ')') {
      if (!current.empty()) tokens.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  if (!current.empty()) tokens.push_back(current);
  return tokens;
}

// Parses the decimal digits of token[from, to) as a positive int, or -1.
int parse_count(const std::string& token, size_t from, size_t to) {
  if (from >= to || to - from > 7) return -1;
  int value = 0;
  for (size_t i = from; i < to; ++i) {
    if (token[i] < '0' || token[i] > '9') return -1;
    value = value * 10 + (token[i] - '0');
  }
  return value;
}

void check_edge(const EdgeType& e, const std::string& where) {
  if (e.n < 2 || e.n > kMaxEdgeCount || e.delay < 1 || e.delay > kMaxEdgeCount)
    throw InvalidInput(where + ": edge type " + (e.kind == EdgeKind::kBezier ? "B" : "C") + std::to_string(e.n) +
                       "^" + std::to_string(e.delay) + " needs n >= 2 and delay >= 1");
}

// A compact map key: every edge as three numbers, then E, the algorithm and the delay.
std::string key_of(const FaceType& face) {
  std::string key;
  key.reserve(16 * (face.boundary.size() + 4));
  auto put = [&key](int value) { key.append(reinterpret_cast<const char*>(&value), sizeof value); };
  auto put_edge = [&put](const EdgeType& e) {
    put(e.kind == EdgeKind::kBezier ? 0 : 1);
    put(e.n);
    put(e.delay);
  };
  for (const EdgeType& e : face.boundary) put_edge(e);
  put(-1);
  put_edge(face.edges.adjacency);
  put_edge(face.edges.lacuna);
  put_edge(face.edges.cantor_gap);
  put(int(face.algorithm));
  put(face.delay);
  return key;
}

FaceType child_face(const FaceRule& rule, const SubFace& sub) {
  FaceType child;
  child.boundary = sub.boundary;
  child.edges = rule.face.edges;
  child.algorithm = rule.face.algorithm;
  child.delay = rule.face.delay >= 2 ? rule.face.delay - 1 : 1;
  return child;
}

// Where a selection starts or ends: an interior subdivision point of an edge (after sub-edge k), or a corner.
struct Cut {
  bool corner = false;
  int edge = -1;    // interior: the edge; corner: the edge that ends there
  int k = -1;       // interior: the sub-edge before the point
  int vertex = -1;  // corner: the face vertex
  bool gap = false;
};

VertexRef foot_of(const Cut& cut) {
  if (cut.corner) return {VertexKind::kLacunaCorner, -1, cut.vertex};
  return {VertexKind::kLacunaEdge, cut.edge, cut.k};
}

// Tarjan's strongly connected components over the child lists.
void strong_components(const std::vector<std::vector<int>>& children, std::vector<std::vector<int>>& components) {
  const int count = int(children.size());
  std::vector<int> index(size_t(count), -1), low(size_t(count), 0), stack;
  std::vector<char> on_stack(size_t(count), 0);
  int next = 0;
  std::function<void(int)> visit = [&](int v) {
    index[size_t(v)] = low[size_t(v)] = next++;
    stack.push_back(v);
    on_stack[size_t(v)] = 1;
    for (int w : children[size_t(v)]) {
      if (index[size_t(w)] < 0) {
        visit(w);
        low[size_t(v)] = std::min(low[size_t(v)], low[size_t(w)]);
      } else if (on_stack[size_t(w)]) {
        low[size_t(v)] = std::min(low[size_t(v)], index[size_t(w)]);
      }
    }
    if (low[size_t(v)] == index[size_t(v)]) {
      std::vector<int> component;
      for (;;) {
        const int w = stack.back();
        stack.pop_back();
        on_stack[size_t(w)] = 0;
        component.push_back(w);
        if (w == v) break;
      }
      std::sort(component.begin(), component.end());
      components.push_back(component);
    }
  };
  for (int v = 0; v < count; ++v)
    if (index[size_t(v)] < 0) visit(v);
}

void check_type(const RuleSet& rules, int type, const char* what) {
  if (type < 0 || type >= int(rules.rules.size()))
    throw InvalidInput(std::string(what) + ": face type " + std::to_string(type) + " is not in the rule set (0.." +
                       std::to_string(int(rules.rules.size()) - 1) + ")");
}

}  // namespace

bool EdgeType::operator<(const EdgeType& o) const {
  if (kind != o.kind) return kind == EdgeKind::kBezier;
  if (n != o.n) return n < o.n;
  return delay < o.delay;
}

std::string to_string(const EdgeType& edge) {
  std::string s = (edge.kind == EdgeKind::kBezier ? "B" : "C") + std::to_string(edge.n);
  if (edge.delay != 1) s += "^" + std::to_string(edge.delay);
  return s;
}

EdgeType parse_edge(const std::string& token) {
  const std::string expected = "expected B or C, then n >= 2, then optionally ^d with d >= 1 (e.g. C4, B2, C2^2)";
  if (token.empty()) throw InvalidInput("empty edge type: " + expected);
  EdgeType edge;
  if (token[0] == 'B')
    edge.kind = EdgeKind::kBezier;
  else if (token[0] == 'C')
    edge.kind = EdgeKind::kCantor;
  else
    throw InvalidInput("edge type '" + token + "': " + expected);
  const size_t caret = token.find('^');
  const size_t n_end = caret == std::string::npos ? token.size() : caret;
  edge.n = parse_count(token, 1, n_end);
  edge.delay = caret == std::string::npos ? 1 : parse_count(token, caret + 1, token.size());
  if (edge.n < 2 || edge.delay < 1) throw InvalidInput("edge type '" + token + "': " + expected);
  return edge;
}

std::vector<EdgeType> parse_boundary(const std::string& text) {
  const std::vector<std::string> tokens = split_tokens(text);
  std::vector<EdgeType> boundary;
  for (size_t i = 0; i < tokens.size(); ++i) {
    try {
      boundary.push_back(parse_edge(tokens[i]));
    } catch (const InvalidInput& e) {
      throw InvalidInput("boundary '" + text + "', edge " + std::to_string(i + 1) + ": " + e.what());
    }
  }
  if (boundary.size() < 2)
    throw InvalidInput("boundary '" + text + "': expected at least 2 edge types such as 'C4 B2 C2 B2'");
  return boundary;
}

EdgeSet parse_edge_set(const std::string& text) {
  const std::vector<std::string> tokens = split_tokens(text);
  if (tokens.size() != 3)
    throw InvalidInput("edge set '" + text + "': expected three edge types 'Ea El Ec' such as 'C2 B2 B2', got " +
                       std::to_string(tokens.size()));
  const char* names[3] = {"Ea", "El", "Ec"};
  EdgeType parsed[3];
  for (int i = 0; i < 3; ++i) {
    try {
      parsed[i] = parse_edge(tokens[size_t(i)]);
    } catch (const InvalidInput& e) {
      throw InvalidInput("edge set '" + text + "', " + names[i] + ": " + e.what());
    }
  }
  return {parsed[0], parsed[1], parsed[2]};
}

std::string to_string(Algorithm algorithm) {
  switch (algorithm) {
    case Algorithm::kA1: return "A1";
    case Algorithm::kA2: return "A2";
    case Algorithm::kA3: return "A3";
  }
  return "A?";
}

Algorithm parse_algorithm(const std::string& text) {
  if (text == "A1") return Algorithm::kA1;
  if (text == "A2") return Algorithm::kA2;
  if (text == "A3") return Algorithm::kA3;
  throw InvalidInput("algorithm '" + text + "': expected A1, A2 or A3");
}

std::string to_string(const FaceType& face) {
  std::string s = "F";
  if (face.delay != 1) s += "^" + std::to_string(face.delay);
  s += "(";
  for (size_t i = 0; i < face.boundary.size(); ++i) s += (i ? " " : "") + to_string(face.boundary[i]);
  s += " | " + to_string(face.edges.adjacency) + " " + to_string(face.edges.lacuna) + " " +
       to_string(face.edges.cantor_gap) + " | " + to_string(face.algorithm) + ")";
  return s;
}

void validate(const FaceType& face) {
  if (face.boundary.size() < 2)
    throw InvalidInput("face " + to_string(face) + ": a boundary needs at least 2 edges");
  if (face.delay < 1 || face.delay > kMaxEdgeCount)
    throw InvalidInput("face " + to_string(face) + ": delay must be >= 1, got " + std::to_string(face.delay));
  for (size_t i = 0; i < face.boundary.size(); ++i)
    check_edge(face.boundary[i], "face boundary edge " + std::to_string(i));
  check_edge(face.edges.adjacency, "Ea");
  check_edge(face.edges.lacuna, "El");
  check_edge(face.edges.cantor_gap, "Ec");
}

int canonical_shift(const std::vector<EdgeType>& boundary) {
  const int count = int(boundary.size());
  int best = 0;
  for (int s = 1; s < count; ++s) {
    for (int j = 0; j < count; ++j) {
      const EdgeType& a = boundary[size_t((s + j) % count)];
      const EdgeType& b = boundary[size_t((best + j) % count)];
      if (a < b) {
        best = s;
        break;
      }
      if (b < a) break;
    }
  }
  return best;
}

std::vector<EdgeType> rotate(const std::vector<EdgeType>& boundary, int shift) {
  const int count = int(boundary.size());
  std::vector<EdgeType> out(boundary.size());
  for (int j = 0; j < count; ++j) out[size_t(j)] = boundary[size_t(((j + shift) % count + count) % count)];
  return out;
}

FaceType canonical(const FaceType& face) {
  FaceType out = face;
  out.boundary = rotate(face.boundary, canonical_shift(face.boundary));
  return out;
}

bool same_boundary(const std::vector<EdgeType>& a, const std::vector<EdgeType>& b) {
  if (a.size() != b.size()) return false;
  return rotate(a, canonical_shift(a)) == rotate(b, canonical_shift(b));
}

bool same_face(const FaceType& a, const FaceType& b) {
  return a.edges == b.edges && a.algorithm == b.algorithm && a.delay == b.delay &&
         same_boundary(a.boundary, b.boundary);
}

std::vector<SubEdge> subdivide(const EdgeType& edge) {
  if (edge.delay >= 2) {
    EdgeType sub = edge;
    sub.delay = edge.delay - 1;
    return {SubEdge{sub, false, false}};
  }
  std::vector<SubEdge> subs(size_t(edge.n), SubEdge{edge, false, false});
  if (edge.kind == EdgeKind::kCantor) {
    for (int k = 0; k < edge.n; ++k) {
      subs[size_t(k)].gap_before = k > 0;
      subs[size_t(k)].gap_after = k + 1 < edge.n;
    }
  }
  return subs;
}

bool in_corner(const EdgeType& edge, int k) {
  const int count = edge.delay >= 2 ? 1 : edge.n;
  return k == 0 || k == count - 1;
}

FaceRule make_rule(const FaceType& face) {
  validate(face);
  FaceRule rule;
  rule.face = face;
  const int count = int(face.boundary.size());
  std::vector<std::vector<SubEdge>> subs;
  for (const EdgeType& e : face.boundary) subs.push_back(subdivide(e));
  const EdgeType& ec = face.edges.cantor_gap;

  if (face.delay >= 2) {
    SubFace sub;
    int next_id = 0;
    for (int i = 0; i < count; ++i) {
      for (int k = 0; k < int(subs[size_t(i)].size()); ++k) {
        sub.boundary.push_back(subs[size_t(i)][size_t(k)].type);
        sub.incidence.push_back({EdgeRole::kParent, i, k, -1});
        sub.vertices.push_back({VertexKind::kBoundary, i, 2 * k});
        if (subs[size_t(i)][size_t(k)].gap_after) {
          sub.boundary.push_back(ec);
          sub.incidence.push_back({EdgeRole::kCantorGap, -1, -1, next_id++});
          sub.vertices.push_back({VertexKind::kBoundary, i, 2 * k + 1});
          sub.boundary.push_back(ec);
          sub.incidence.push_back({EdgeRole::kCantorGap, -1, -1, next_id++});
          sub.vertices.push_back({VertexKind::kNotchApex, i, k});
        }
      }
    }
    rule.subfaces.push_back(sub);
    rule.interior_edge_count = next_id;
    rule.lacunas = 0;
    return rule;
  }

  // The sub-edges counter-clockwise, and whether an adjacency point follows each one.
  struct Position {
    int edge, k;
  };
  std::vector<Position> seq;
  seq.reserve(size_t(4 * count));
  for (int i = 0; i < count; ++i)
    for (int k = 0; k < int(subs[size_t(i)].size()); ++k) seq.push_back({i, k});
  const int m = int(seq.size());
  std::vector<Cut> cut_after(static_cast<size_t>(m));
  std::vector<char> is_cut(size_t(m), 0);
  auto corner_cut = [&](int edge_before) {
    const int edge_after = (edge_before + 1) % count;
    switch (face.algorithm) {
      case Algorithm::kA1: return false;
      case Algorithm::kA2: return true;
      case Algorithm::kA3:
        return face.boundary[size_t(edge_before)].delay >= 2 || face.boundary[size_t(edge_after)].delay >= 2;
    }
    return false;
  };
  int cuts = 0;
  for (int j = 0; j < m; ++j) {
    const Position p = seq[size_t(j)];
    Cut& c = cut_after[size_t(j)];
    if (p.k + 1 < int(subs[size_t(p.edge)].size())) {
      c.edge = p.edge;
      c.k = p.k;
      c.gap = subs[size_t(p.edge)][size_t(p.k)].gap_after;
      is_cut[size_t(j)] = 1;
    } else {
      c.corner = true;
      c.edge = p.edge;
      c.vertex = (p.edge + 1) % count;
      is_cut[size_t(j)] = corner_cut(p.edge);
    }
    cuts += is_cut[size_t(j)];
  }
  if (cuts < 2) {
    // Fewer than two adjacency points would leave a sub-face wrapped around the lacuna: use A2's corners.
    for (int j = 0; j < m; ++j)
      if (cut_after[size_t(j)].corner) is_cut[size_t(j)] = 1;
  }

  // Runs of sub-edges between adjacency points, starting with the run that holds sub-edge 0 of edge 0.
  int start = 0;
  while (!is_cut[size_t((start - 1 + m) % m)]) start = (start - 1 + m) % m;
  std::vector<std::vector<int>> runs;
  for (int step = 0; step < m; ++step) {
    const int j = (start + step) % m;
    if (step == 0 || is_cut[size_t((j - 1 + m) % m)]) runs.emplace_back();
    runs.back().push_back(j);
  }
  const int run_count = int(runs.size());
  rule.subfaces.reserve(runs.size());
  rule.adjacency.reserve(runs.size());
  int next_ec = 2 * run_count;  // Ea ids 0..R-1 (the cut after run r), El ids R..2R-1
  std::vector<int> ea_out(static_cast<size_t>(run_count)), ea_in(static_cast<size_t>(run_count));
  for (int r = 0; r < run_count; ++r) {
    const std::vector<int>& run = runs[size_t(r)];
    const Position last = seq[size_t(run.back())];
    const Cut& end_cut = cut_after[size_t(run.back())];
    const Cut& start_cut = cut_after[size_t((run.front() - 1 + m) % m)];
    SubFace sub;
    const size_t edges = run.size() + 5;
    sub.boundary.reserve(edges);
    sub.incidence.reserve(edges);
    sub.vertices.reserve(edges);
    for (int j : run) {
      const Position p = seq[size_t(j)];
      sub.boundary.push_back(subs[size_t(p.edge)][size_t(p.k)].type);
      sub.incidence.push_back({EdgeRole::kParent, p.edge, p.k, -1});
      sub.vertices.push_back({VertexKind::kBoundary, p.edge, 2 * p.k});
    }
    const VertexRef end_point{VertexKind::kBoundary, last.edge, 2 * last.k + 1};
    if (end_cut.gap) {
      sub.boundary.push_back(ec);
      sub.incidence.push_back({EdgeRole::kCantorGap, -1, -1, next_ec++});
      sub.vertices.push_back(end_point);
      ea_out[size_t(r)] = int(sub.boundary.size());
      sub.vertices.push_back({VertexKind::kNotchApex, end_cut.edge, end_cut.k});
    } else {
      ea_out[size_t(r)] = int(sub.boundary.size());
      sub.vertices.push_back(end_point);
    }
    sub.boundary.push_back(face.edges.adjacency);
    sub.incidence.push_back({EdgeRole::kAdjacency, -1, -1, r});
    sub.boundary.push_back(face.edges.lacuna);
    sub.incidence.push_back({EdgeRole::kLacuna, -1, -1, run_count + r});
    sub.vertices.push_back(foot_of(end_cut));
    ea_in[size_t(r)] = int(sub.boundary.size());
    sub.boundary.push_back(face.edges.adjacency);
    sub.incidence.push_back({EdgeRole::kAdjacency, -1, -1, (r - 1 + run_count) % run_count});
    sub.vertices.push_back(foot_of(start_cut));
    if (start_cut.gap) {
      sub.boundary.push_back(ec);
      sub.incidence.push_back({EdgeRole::kCantorGap, -1, -1, next_ec++});
      sub.vertices.push_back({VertexKind::kNotchApex, start_cut.edge, start_cut.k});
    }
    rule.subfaces.push_back(std::move(sub));
  }
  for (int r = 0; r < run_count; ++r) {
    const int next = (r + 1) % run_count;
    rule.adjacency.push_back({r, r, ea_out[size_t(r)], next, ea_in[size_t(next)]});
  }
  rule.interior_edge_count = next_ec;
  rule.lacunas = 1;
  for (const EdgeType& e : face.boundary)
    if (e.kind == EdgeKind::kCantor && e.delay == 1) rule.lacunas += 0.5 * (e.n - 1);
  return rule;
}

RuleSet build_rules(const std::vector<FaceType>& roots, const ClosureOptions& options) {
  if (roots.empty()) throw InvalidInput("build_rules: no root face");
  RuleSet set;
  std::unordered_map<std::string, int> ids;
  auto intern = [&](FaceType face) {
    face.boundary = rotate(face.boundary, canonical_shift(face.boundary));
    const FaceType& c = face;
    const std::string key = key_of(c);
    const auto found = ids.find(key);
    if (found != ids.end()) return found->second;
    if (int(set.rules.size()) >= options.max_types)
      throw ResourceLimit("the rule set of " + to_string(roots[0]) + " has more than " +
                          std::to_string(options.max_types) + " face types (ClosureOptions::max_types)");
    const int id = int(set.rules.size());
    ids.emplace(key, id);
    FaceRule placeholder;
    placeholder.face = c;
    set.rules.push_back(placeholder);
    return id;
  };
  for (const FaceType& root : roots) {
    validate(root);
    set.roots.push_back(intern(root));
  }
  for (size_t t = 0; t < set.rules.size(); ++t) {  // the vector grows: breadth-first order
    FaceRule rule = make_rule(set.rules[t].face);
    for (SubFace& sub : rule.subfaces) {
      sub.shift = canonical_shift(sub.boundary);
      sub.type = intern(child_face(rule, sub));
    }
    set.rules[t] = std::move(rule);
  }
  std::vector<std::vector<int>> children(set.rules.size());
  for (size_t t = 0; t < set.rules.size(); ++t) {
    for (const SubFace& sub : set.rules[t].subfaces) children[t].push_back(sub.type);
    if (std::find(children[t].begin(), children[t].end(), int(t)) != children[t].end())
      set.self_reproducing.push_back(int(t));
  }
  std::vector<std::vector<int>> components;
  strong_components(children, components);
  for (const std::vector<int>& c : components) {
    const bool self_loop = std::find(children[size_t(c[0])].begin(), children[size_t(c[0])].end(), c[0]) !=
                           children[size_t(c[0])].end();
    if (c.size() > 1 || self_loop) set.cycles.push_back(c);
  }
  std::sort(set.cycles.begin(), set.cycles.end());
  return set;
}

RuleSet build_rules(const FaceType& root, const ClosureOptions& options) {
  return build_rules(std::vector<FaceType>{root}, options);
}

int find_type(const RuleSet& rules, const FaceType& face) {
  const FaceType c = canonical(face);
  for (size_t t = 0; t < rules.rules.size(); ++t) {
    const FaceType& f = rules.rules[t].face;
    if (f.boundary == c.boundary && f.edges == c.edges && f.algorithm == c.algorithm && f.delay == c.delay)
      return int(t);
  }
  return -1;
}

Eigen::MatrixXd substitution_matrix(const RuleSet& rules) {
  const Eigen::Index count = Eigen::Index(rules.rules.size());
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(count, count);
  for (Eigen::Index t = 0; t < count; ++t)
    for (const SubFace& sub : rules.rules[size_t(t)].subfaces) s(t, sub.type) += 1;
  return s;
}

Lacunarity lacunarity(const RuleSet& rules, int type, int levels) {
  check_type(rules, type, "lacunarity");
  if (levels < 0) throw InvalidInput("lacunarity: levels must be >= 0, got " + std::to_string(levels));
  // Restrict to the types reachable from `type`: the others do not affect its counts.
  std::vector<int> local(rules.rules.size(), -1), reach{type};
  local[size_t(type)] = 0;
  for (size_t q = 0; q < reach.size(); ++q)
    for (const SubFace& sub : rules.rules[size_t(reach[q])].subfaces)
      if (local[size_t(sub.type)] < 0) {
        local[size_t(sub.type)] = int(reach.size());
        reach.push_back(sub.type);
      }
  const Eigen::Index count = Eigen::Index(reach.size());
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(count, count);
  Eigen::VectorXd l(count);
  for (Eigen::Index t = 0; t < count; ++t) {
    const FaceRule& rule = rules.rules[size_t(reach[size_t(t)])];
    l(t) = rule.lacunas;
    for (const SubFace& sub : rule.subfaces) s(t, local[size_t(sub.type)]) += 1;
  }

  return lacunarity(s, l, levels);
}

Lacunarity lacunarity(const Eigen::MatrixXd& s, const Eigen::VectorXd& l, int levels) {
  const Eigen::Index count = s.rows();
  if (count < 1 || s.cols() != count || l.size() != count || levels < 0)
    throw InvalidInput("lacunarity: expected a square substitution matrix, one lacuna count per type and levels >= 0");
  Lacunarity out;
  Eigen::VectorXd c = Eigen::VectorXd::Ones(count), lac = Eigen::VectorXd::Zero(count);
  for (int i = 0; i <= levels; ++i) {
    if (i > 0) {
      lac = l + s * lac;
      c = s * c;
    }
    out.subfaces.push_back(c(0));
    out.lacunas.push_back(lac(0));
    out.ratio.push_back(lac(0) / (c(0) + lac(0)));
  }

  const Eigen::VectorXcd eigenvalues = Eigen::EigenSolver<Eigen::MatrixXd>(s, false).eigenvalues();
  double rho = 0;
  for (Eigen::Index k = 0; k < count; ++k) rho = std::max(rho, std::abs(eigenvalues(k)));
  out.spectral_radius = rho;
  int on_circle = 0;
  for (Eigen::Index k = 0; k < count; ++k)
    if (std::abs(eigenvalues(k)) > rho * (1 - 1e-6)) ++on_circle;  // a defective pair splits by ~1e-8

  if (rho > 1 + 1e-9 && on_circle == 1) {
    // Left Perron vector: the limit of the lazy iteration (I + S^T / rho) / 2, squared until it stops changing.
    Eigen::MatrixXd q = 0.5 * (Eigen::MatrixXd::Identity(count, count) + s.transpose() / rho);
    // Normalised at every step: only the direction matters, and rounding in rho would otherwise make q^(2^k)
    // decay or blow up.
    for (int step = 0; step < 64; ++step) {
      Eigen::MatrixXd q2 = q * q;
      q2 /= q2.maxCoeff();
      const double change = (q2 - q).cwiseAbs().maxCoeff();
      q.swap(q2);
      if (change <= 1e-13) break;
    }
    Eigen::VectorXd w = q * Eigen::VectorXd::Ones(count);
    w /= w.maxCoeff();
    const double wl = w.dot(l), w1 = w.sum();
    out.limit = wl / (wl + (rho - 1) * w1);
    if (std::isfinite(out.limit)) return out;
  }
  // Iterate with a common scale sigma: c' = c / sigma, L' = L / sigma.
  Eigen::VectorXd cs = Eigen::VectorXd::Ones(count), ls = Eigen::VectorXd::Zero(count);
  double inv_sigma = 1, previous = 0;
  out.limit = 0;
  for (int i = 1; i <= 100000; ++i) {
    ls = l * inv_sigma + s * ls;
    cs = s * cs;
    const double scale = std::max(1.0, cs.maxCoeff());
    cs /= scale;
    ls /= scale;
    inv_sigma /= scale;
    const double r = ls(0) / (cs(0) + ls(0));
    out.limit = r;
      // Past the transient (a delayed chain is at most `count` long) and settled.
    if (i > count + 2 && std::fabs(r - previous) < 1e-14) break;
    previous = r;
  }
  return out;
}

void validate(const Assembly& assembly) {
  const int faces = int(assembly.faces.size());
  for (int f = 0; f < faces; ++f) {
    try {
      validate(assembly.faces[size_t(f)]);
    } catch (const InvalidInput& e) {
      throw InvalidInput("assembly face " + std::to_string(f) + ": " + e.what());
    }
  }
  std::set<std::pair<int, int>> used;
  for (size_t s = 0; s < assembly.shared.size(); ++s) {
    const SharedEdge& e = assembly.shared[s];
    const std::string where = "assembly shared edge " + std::to_string(s) + " (face " + std::to_string(e.face_a) +
                              " edge " + std::to_string(e.edge_a) + " = face " + std::to_string(e.face_b) +
                              " edge " + std::to_string(e.edge_b) + ")";
    for (const auto& side : {std::make_pair(e.face_a, e.edge_a), std::make_pair(e.face_b, e.edge_b)}) {
      if (side.first < 0 || side.first >= faces)
        throw InvalidInput(where + ": face index out of range 0.." + std::to_string(faces - 1));
      const int edges = int(assembly.faces[size_t(side.first)].boundary.size());
      if (side.second < 0 || side.second >= edges)
        throw InvalidInput(where + ": edge index out of range 0.." + std::to_string(edges - 1));
      if (!used.insert(side).second)
        throw InvalidInput(where + ": face " + std::to_string(side.first) + " edge " +
                           std::to_string(side.second) + " is shared more than once");
    }
    const EdgeType& a = assembly.faces[size_t(e.face_a)].boundary[size_t(e.edge_a)];
    const EdgeType& b = assembly.faces[size_t(e.face_b)].boundary[size_t(e.edge_b)];
    if (a != b)
      throw InvalidInput(where + ": the two sides have different types " + to_string(a) + " and " + to_string(b) +
                         "; a shared edge needs the same kind, n and delay on both sides");
  }
}

std::vector<std::string> edge_trace(const RuleSet& rules, int type, int edge, int levels) {
  check_type(rules, type, "edge_trace");
  if (edge < 0 || edge >= int(rules.rules[size_t(type)].face.boundary.size()))
    throw InvalidInput("edge_trace: edge " + std::to_string(edge) + " is not an edge of " +
                       to_string(rules.rules[size_t(type)].face));
  std::vector<std::string> out;
  std::function<void(int, int, int)> trace = [&](int t, int e, int level) {
    const FaceRule& rule = rules.rules[size_t(t)];
    const EdgeType& edge_type = rule.face.boundary[size_t(e)];
    if (level == 0) {
      out.push_back(to_string(edge_type));
      return;
    }
    const std::vector<SubEdge> subs = subdivide(edge_type);
    for (int k = 0; k < int(subs.size()); ++k) {
      if (k > 0) out.push_back(subs[size_t(k)].gap_before ? "|" : ".");
      int found_face = -1, found_edge = -1, hits = 0;
      for (size_t s = 0; s < rule.subfaces.size(); ++s)
        for (size_t j = 0; j < rule.subfaces[s].incidence.size(); ++j) {
          const Incidence& inc = rule.subfaces[s].incidence[j];
          if (inc.role == EdgeRole::kParent && inc.parent_edge == e && inc.sub_edge == k) {
            found_face = int(s);
            found_edge = int(j);
            ++hits;
          }
        }
      if (hits != 1)
        throw InvalidInput("edge_trace: sub-edge " + std::to_string(k) + " of edge " + std::to_string(e) + " of " +
                           to_string(rule.face) + " is covered " + std::to_string(hits) + " times");
      const SubFace& sub = rule.subfaces[size_t(found_face)];
      if (sub.boundary[size_t(found_edge)] != subs[size_t(k)].type)
        throw InvalidInput("edge_trace: sub-edge " + std::to_string(k) + " of edge " + std::to_string(e) + " of " +
                           to_string(rule.face) + " has the wrong type");
      const int n = int(sub.boundary.size());
      trace(sub.type, ((found_edge - sub.shift) % n + n) % n, level - 1);
    }
  };
  trace(type, edge, levels);
  return out;
}

AssemblyReport check_topology(const Assembly& assembly, const RuleSet& rules, int levels) {
  validate(assembly);
  AssemblyReport report;
  std::vector<int> types, shifts;
  for (size_t f = 0; f < assembly.faces.size(); ++f) {
    const int t = find_type(rules, assembly.faces[f]);
    if (t < 0)
      throw InvalidInput("check_topology: assembly face " + std::to_string(f) + " " + to_string(assembly.faces[f]) +
                         " is not in the rule set");
    types.push_back(t);
    shifts.push_back(canonical_shift(assembly.faces[f].boundary));
  }
  auto canonical_edge = [&](int f, int e) {
    const int n = int(assembly.faces[size_t(f)].boundary.size());
    return ((e - shifts[size_t(f)]) % n + n) % n;
  };
  for (size_t s = 0; s < assembly.shared.size(); ++s) {
    const SharedEdge& e = assembly.shared[s];
    for (int level = 1; level <= levels; ++level) {
      const std::vector<std::string> a = edge_trace(rules, types[size_t(e.face_a)], canonical_edge(e.face_a, e.edge_a), level);
      std::vector<std::string> b = edge_trace(rules, types[size_t(e.face_b)], canonical_edge(e.face_b, e.edge_b), level);
      std::reverse(b.begin(), b.end());
      if (a != b) {
        report.consistent = false;
        report.problems.push_back("shared edge " + std::to_string(s) + " (face " + std::to_string(e.face_a) +
                                  " edge " + std::to_string(e.edge_a) + ", face " + std::to_string(e.face_b) +
                                  " edge " + std::to_string(e.edge_b) + ") differs at level " +
                                  std::to_string(level));
      }
    }
  }
  return report;
}

nlohmann::json rules_json(const RuleSet& rules, int root) {
  check_type(rules, root, "rules_json");
  using nlohmann::json;
  auto edges_json = [](const std::vector<EdgeType>& edges) {
    json a = json::array();
    for (const EdgeType& e : edges) a.push_back(to_string(e));
    return a;
  };
  json types = json::array();
  for (size_t t = 0; t < rules.rules.size(); ++t) {
    const FaceRule& rule = rules.rules[t];
    json children = json::array(), subfaces = json::array(), adjacency = json::array();
    for (const SubFace& sub : rule.subfaces) {
      children.push_back(sub.type);
      json incidence = json::array();
      for (const Incidence& inc : sub.incidence) {
        switch (inc.role) {
          case EdgeRole::kParent:
            incidence.push_back({{"role", "parent"}, {"edge", inc.parent_edge}, {"sub_edge", inc.sub_edge}});
            break;
          case EdgeRole::kAdjacency: incidence.push_back({{"role", "Ea"}, {"id", inc.interior_edge}}); break;
          case EdgeRole::kLacuna: incidence.push_back({{"role", "El"}, {"id", inc.interior_edge}}); break;
          case EdgeRole::kCantorGap: incidence.push_back({{"role", "Ec"}, {"id", inc.interior_edge}}); break;
        }
      }
      subfaces.push_back(
          {{"boundary", edges_json(sub.boundary)}, {"type", sub.type}, {"shift", sub.shift}, {"incidence", incidence}});
    }
    for (const Adjacency& a : rule.adjacency)
      adjacency.push_back({{"id", a.interior_edge},
                           {"face_a", a.face_a},
                           {"edge_a", a.edge_a},
                           {"face_b", a.face_b},
                           {"edge_b", a.edge_b}});
    types.push_back({{"id", int(t)},
                     {"boundary", edges_json(rule.face.boundary)},
                     {"delay", rule.face.delay},
                     {"algorithm", to_string(rule.face.algorithm)},
                     {"edges",
                      {{"Ea", to_string(rule.face.edges.adjacency)},
                       {"El", to_string(rule.face.edges.lacuna)},
                       {"Ec", to_string(rule.face.edges.cantor_gap)}}},
                     {"children", children},
                     {"subfaces", subfaces},
                     {"adjacency", adjacency},
                     {"lacunas_1", rule.lacunas}});
  }
  const Lacunarity measures = lacunarity(rules, root, 1);
  return {{"face_types", types},
          {"root", root},
          {"lacunas_1", measures.lacunas[1]},
          {"subfaces_1", measures.subfaces[1]},
          {"r_limit", measures.limit},
          {"spectral_radius", measures.spectral_radius},
          {"self_reproducing", rules.self_reproducing},
          {"cycles", rules.cycles}};
}

}  // namespace bcifs
}  // namespace lacuna
