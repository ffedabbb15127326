// Lacunar fractal faces, topology (../shared/spec/bcifs-lacunar.md): edge and face types, the subdivision rules
// that algorithms A1, A2 and A3 write from a face's boundary, the closure of a face's rule set, its topological
// lacunarity measures, and the consistency of assemblies of faces that share edges. No geometry here: where a
// sub-face's vertices lie is only named (VertexRef) and computed in bcifs/realize.h.
//
// Interpretations of the spec, in one place:
// - Sub-edges and corners: sub-edge k of an edge is "in a corner" when it touches a vertex of the face (k = 0 or
//   k = count - 1). A delayed edge has a single sub-edge, which touches both corners, so it is in a corner at both
//   ends.
// - Adjacency points: every algorithm puts an adjacency (Ea) edge at every interior subdivision point of an edge
//   (where two connected Bézier sub-edges meet, or at a Cantor gap); A1 puts none at the face's corners, A2 puts
//   one at every corner, A3 at the two corners of every delayed edge. A selection (one sub-face) is a maximal run
//   of consecutive sub-edges between two adjacency points; for non-delayed edges this is exactly the spec's "one
//   sub-edge not in a corner, or the two sub-edges that meet at a corner". Under A1 the single sub-edge of a
//   delayed edge therefore joins the corner selections on both sides into one run of three (or more) sub-edges.
//   When a placement yields fewer than two adjacency points (every edge delayed, or one B2 among delayed edges),
//   a sub-face would wrap around the lacuna; the face then uses A2's placement (adjacency at every corner).
// - Ec: appended after the run when its last sub-edge ends at a Cantor gap, and before it (at the end of the
//   written boundary) when its first sub-edge starts at one. For non-delayed A1 that is the spec's "the last (first)
//   edge of the selection is a Cantor sub-edge"; for A2 it is "X's own gap sides".
// - Order: the sub-faces of a rule are listed counter-clockwise starting with the selection that holds the first
//   sub-edge of boundary edge 0, and each written boundary starts with its selection's first sub-edge.
// - Delayed faces: F^d (d >= 2) has one sub-face F^(d-1) whose boundary is every sub-edge in order with Ec, Ec
//   inserted in every Cantor gap; it keeps E and A. Sub-faces of a non-delayed face have delay 1.
// - Lacunas at level 1: 1 + sum over the boundary's non-delayed Cantor edges Cn of (n - 1) / 2 (a delayed Cantor
//   edge has no gap at this level); 0 for a delayed face.
// - Order of edge types (for the canonical rotation): B before C, then n ascending, then delay ascending.
#pragma once

#include <Eigen/Dense>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace lacuna {
namespace bcifs {

enum class EdgeKind { kBezier, kCantor };  // written B and C

struct EdgeType {
  EdgeKind kind = EdgeKind::kBezier;
  int n = 2;      // number of sub-edges, >= 2
  int delay = 1;  // >= 1; a delay d >= 2 subdivides into one sub-edge of delay d - 1

  bool operator==(const EdgeType& o) const { return kind == o.kind && n == o.n && delay == o.delay; }
  bool operator!=(const EdgeType& o) const { return !(*this == o); }
  bool operator<(const EdgeType& o) const;  // B < C, then n, then delay
};

// "C4", "B2", "C2^3" (delay 1 is written without ^).
std::string to_string(const EdgeType& edge);
// Parses one edge token; throws InvalidInput naming the token and the expected form (B or C, n >= 2, optional ^d
// with d >= 1).
EdgeType parse_edge(const std::string& token);
// Parses a boundary such as "C4 B2 C2 B2 C3 B2" (tokens separated by spaces, commas or both, optionally inside
// < > or ⟨ ⟩); throws InvalidInput naming the bad token and its position, or when there are fewer than 2 edges.
std::vector<EdgeType> parse_boundary(const std::string& text);

// E: the types of the new interior edges of a rule.
struct EdgeSet {
  EdgeType adjacency{EdgeKind::kBezier, 2, 1};   // Ea: shared by two sub-faces, from the lacuna to the boundary
  EdgeType lacuna{EdgeKind::kBezier, 2, 1};      // El: a side of the central lacuna
  EdgeType cantor_gap{EdgeKind::kBezier, 2, 1};  // Ec: closes a sub-face at a Cantor gap (two of them: a notch)

  bool operator==(const EdgeSet& o) const {
    return adjacency == o.adjacency && lacuna == o.lacuna && cantor_gap == o.cantor_gap;
  }
};

// Parses "Ea El Ec", e.g. "C2 B2 B2"; throws InvalidInput unless there are exactly three valid edge tokens.
EdgeSet parse_edge_set(const std::string& text);

enum class Algorithm { kA1, kA2, kA3 };

std::string to_string(Algorithm algorithm);           // "A1", "A2", "A3"
Algorithm parse_algorithm(const std::string& text);  // throws InvalidInput unless A1, A2 or A3

// A face type F^d(boundary, E, A).
struct FaceType {
  std::vector<EdgeType> boundary;  // counter-clockwise, at least 2 edges
  EdgeSet edges;                   // E
  Algorithm algorithm = Algorithm::kA1;
  int delay = 1;  // >= 1; d >= 2 creates no lacuna and one sub-face of delay d - 1
};

// "F(C2 B2 C2 B2 C2 B2 | C2 B2 B2 | A1)", "F^2(...)" for a delay, boundary as stored (not rotated).
std::string to_string(const FaceType& face);
// Throws InvalidInput unless the boundary has at least 2 edges and every n >= 2 and delay >= 1.
void validate(const FaceType& face);

// The shift s of the lexicographically smallest circular shift: canonical[j] = boundary[(j + s) % N]; the
// smallest such s when the boundary is periodic.
int canonical_shift(const std::vector<EdgeType>& boundary);
std::vector<EdgeType> rotate(const std::vector<EdgeType>& boundary, int shift);  // result[j] = boundary[(j+s)%N]
FaceType canonical(const FaceType& face);  // boundary rotated by canonical_shift
// Equal boundaries up to circular shift (never reflection).
bool same_boundary(const std::vector<EdgeType>& a, const std::vector<EdgeType>& b);
// Same face type: boundary up to circular shift, same E, algorithm and delay.
bool same_face(const FaceType& a, const FaceType& b);

// One sub-edge of an edge's subdivision.
struct SubEdge {
  EdgeType type;
  bool gap_before = false;  // a Cantor gap separates it from the previous sub-edge of the same edge
  bool gap_after = false;   // a Cantor gap separates it from the next sub-edge of the same edge
};

// Bn -> n connected Bn; Cn -> n Cn with a gap between consecutive ones; Xn^d -> one Xn^(d-1) (no gap).
std::vector<SubEdge> subdivide(const EdgeType& edge);
// Whether sub-edge k of the edge touches a vertex of the face: k == 0 or k == count - 1 (so always for n = 2, and
// for the single sub-edge of a delayed edge).
bool in_corner(const EdgeType& edge, int k);

// Which edge of the parent a sub-face's edge is.
enum class EdgeRole { kParent, kAdjacency, kLacuna, kCantorGap };

struct Incidence {
  EdgeRole role = EdgeRole::kParent;
  int parent_edge = -1;    // kParent: index of the parent's boundary edge
  int sub_edge = -1;       // kParent: index of the sub-edge along it, 0 at the parent edge's start
  int interior_edge = -1;  // other roles: id of the new interior edge within the rule (Ea ids are shared)
};

// Where a sub-face vertex lies, in terms of the parent's control polygon (realize.h turns it into a point).
enum class VertexKind {
  kBoundary,      // on parent edge `edge`: index 2k is the start of sub-edge k, 2k + 1 its end
  kNotchApex,     // apex of the notch in the gap after sub-edge `index` of Cantor edge `edge`
  kLacunaCorner,  // vertex `index` of the lacuna (the copy of parent vertex `index`)
  kLacunaEdge,    // on lacuna edge `edge`, at the parameter of the point after sub-edge `index` of parent edge `edge`
};

struct VertexRef {
  VertexKind kind = VertexKind::kBoundary;
  int edge = -1;
  int index = -1;
};

struct SubFace {
  std::vector<EdgeType> boundary;    // as written by the algorithm, counter-clockwise
  std::vector<Incidence> incidence;  // one per boundary edge
  std::vector<VertexRef> vertices;   // the start vertex of each boundary edge
  int type = -1;                     // face-type id in a RuleSet; -1 from make_rule
  int shift = 0;  // the type's canonical boundary[j] is boundary[(j + shift) % N]
};

// Two sub-faces share an Ea edge: edge_a of face_a runs from the boundary to the lacuna, edge_b of face_b is the
// same edge the other way.
struct Adjacency {
  int interior_edge = -1;
  int face_a = -1, edge_a = -1;
  int face_b = -1, edge_b = -1;
};

struct FaceRule {
  FaceType face;                    // the face the rule subdivides (canonical in a RuleSet)
  std::vector<SubFace> subfaces;    // counter-clockwise, see the order above
  std::vector<Adjacency> adjacency;  // one per Ea edge, in the order of the sub-faces
  double lacunas = 0;               // N^L_1 of this face
  int interior_edge_count = 0;      // ids 0 .. count-1: Ea edges first, then El, then Ec
};

// The rule the face's algorithm writes (non-delayed: A1/A2/A3; delayed: one notched sub-face). Edge indices refer
// to face.boundary as given (not rotated). Throws InvalidInput when validate() does.
FaceRule make_rule(const FaceType& face);

struct ClosureOptions {
  int max_types = 10000;  // ResourceLimit beyond this many face types
};

// The rule set reachable from one or more root faces: rules[t] is the rule of face type t (its face is
// canonical), ids in breadth-first discovery order, roots first (root ids 0, 1, ... unless two roots are the same
// type). Throws InvalidInput for an invalid root and ResourceLimit past options.max_types.
struct RuleSet {
  std::vector<FaceRule> rules;
  std::vector<int> roots;                  // the type id of each root, in the order given
  std::vector<int> self_reproducing;       // types whose children include themselves, ascending
  std::vector<std::vector<int>> cycles;    // strongly connected components with a cycle (size > 1, or a
                                           // self-loop), each ascending, sorted by first id
};

RuleSet build_rules(const std::vector<FaceType>& roots, const ClosureOptions& options = {});
RuleSet build_rules(const FaceType& root, const ClosureOptions& options = {});
// The id of a face type in the set, or -1.
int find_type(const RuleSet& rules, const FaceType& face);

// S (types x types): S(t, u) = number of sub-faces of type u in the rule of t.
Eigen::MatrixXd substitution_matrix(const RuleSet& rules);

struct Lacunarity {
  std::vector<double> subfaces;  // N^C_i, i = 0..levels
  std::vector<double> lacunas;   // N^L_i
  std::vector<double> ratio;     // R_i = N^L_i / (N^C_i + N^L_i) (R_0 = 0)
  double spectral_radius = 0;    // rho(S)
  // lim R_i. For rho > 1 with a simple dominant eigenvalue: N^C_i ~ rho^i v (w.1) and N^L_i ~ rho^i v (w.l)/(rho-1)
  // for the left Perron vector w and level-1 lacuna vector l, so R = w.l / (w.l + (rho - 1) w.1). Otherwise R_i is
  // iterated (normalised) until it changes by less than 1e-14 or 100000 levels.
  double limit = 0;
};

// The topological measures of face type `type` for levels 0..levels. Throws InvalidInput for a bad type or
// levels < 0.
Lacunarity lacunarity(const RuleSet& rules, int type, int levels);
// The same for type 0 of any substitution system: s(t, u) children of type u in the rule of t, l(t) the lacunas a
// rule of type t makes at level 1 (lacunar volumes count their cells this way). Throws InvalidInput unless s is
// square with one l per row and levels >= 0.
Lacunarity lacunarity(const Eigen::MatrixXd& s, const Eigen::VectorXd& l, int levels);

// The rule set as JSON: face_types [{id, boundary (canonical, ["C2", ...]), delay, algorithm, edges {Ea, El, Ec},
// children (one id per sub-face), subfaces [{boundary as written, type, shift, incidence}], adjacency, lacunas_1}],
// root, lacunas_1 and subfaces_1 of the root, r_limit, spectral_radius, self_reproducing, cycles.
nlohmann::json rules_json(const RuleSet& rules, int root = 0);

// Faces that share edges. Each face keeps its own boundary (as written), E, algorithm and delay.
struct SharedEdge {
  int face_a = -1, edge_a = -1;  // edge_a of face_a (index into that face's boundary as written)
  int face_b = -1, edge_b = -1;  // is edge_b of face_b, traversed the other way
};

struct Assembly {
  std::vector<FaceType> faces;
  std::vector<SharedEdge> shared;
};

// Throws InvalidInput for an invalid face, an index out of range, an edge shared twice, or two sides of different
// types (kind, n, delay), naming the faces, edges and types.
void validate(const Assembly& assembly);

// The leaf sub-edges along edge `edge` (canonical index) of face type `type` after `levels` subdivisions, found by
// following the rules' incidences: edge tokens ("C2") separated by "|" (a Cantor gap) or "." (connected).
// Throws InvalidInput when a rule does not cover each sub-edge exactly once with a sub-face edge of its type.
std::vector<std::string> edge_trace(const RuleSet& rules, int type, int edge, int levels);

struct AssemblyReport {
  bool consistent = true;
  std::vector<std::string> problems;  // one line per shared edge and level that disagree
};

// Whether, at every level 1..levels, both sides of every shared edge subdivide it into the same sub-edges (types,
// gaps in the same places) in reverse order. `rules` must hold every face of the assembly (build_rules of the
// faces). Throws InvalidInput when validate(assembly) does.
AssemblyReport check_topology(const Assembly& assembly, const RuleSet& rules, int levels);

}  // namespace bcifs
}  // namespace lacuna
