#include "recipe/cifs_system.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "cifs/junction.h"
#include "cifs/library.h"
#include "cifs/nurbs.h"
#include "errors.h"
#include "recipe/json_fields.h"

namespace lacuna {
namespace cifs {
namespace {


Eigen::MatrixXd parse_matrix(const JsonObject& o, const char* key) {
  const nlohmann::json& rows = o.required(key);
  if (!rows.is_array() || rows.empty() || !rows[0].is_array() || rows[0].empty())
    o.fail(key, "expected a matrix as a list of rows of numbers");
  Eigen::MatrixXd m(Eigen::Index(rows.size()), Eigen::Index(rows[0].size()));
  for (size_t i = 0; i < rows.size(); ++i) {
    if (!rows[i].is_array() || rows[i].size() != rows[0].size())
      o.fail(std::string(key) + "[" + std::to_string(i) + "]", "every row needs " + std::to_string(rows[0].size()) + " numbers");
    for (size_t j = 0; j < rows[i].size(); ++j) {
      if (!rows[i][j].is_number()) o.fail(std::string(key) + "[" + std::to_string(i) + "]", "expected numbers");
      m(Eigen::Index(i), Eigen::Index(j)) = rows[i][j].get<double>();
    }
  }
  return m;
}

std::vector<double> parse_numbers(const JsonObject& o, const char* key) {
  const nlohmann::json& v = o.required(key);
  if (!v.is_array()) o.fail(key, "expected a list of numbers");
  std::vector<double> out;
  for (const auto& x : v) {
    if (!x.is_number()) o.fail(key, "expected a list of numbers");
    out.push_back(x.get<double>());
  }
  return out;
}

int parse_int(const JsonObject& o, const char* key) {
  const nlohmann::json& v = o.required(key);
  if (!v.is_number_integer()) o.fail(key, "expected an integer");
  return v.get<int>();
}

// An explicit automaton: {"states": [...], "transitions": [...], "initial", "alphabet_size"}.
// Transition matrices are optional for patterns.
Automaton parse_automaton(const JsonObject& o, bool with_matrices) {
  Automaton a;
  const nlohmann::json& states = o.required("states");
  if (!states.is_array() || states.empty()) o.fail("states", "expected a non-empty list of states");
  std::map<std::string, int> index;
  for (size_t i = 0; i < states.size(); ++i) {
    JsonObject s(states[i], o.file(), o.path_of("states[" + std::to_string(i) + "]"));
    State st;
    if (with_matrices) {
      s.allow_only({"name", "control_points", "primitive", "vertices", "faces"});
      st.control_points = parse_int(s, "control_points");
      if (st.control_points < 1 || st.control_points > 4096) s.fail("control_points", "expected 1 .. 4096");
      try {
        st.primitive = primitive_from_name(s.string_or("primitive", "segment"));
      } catch (const InvalidInput& e) {
        s.fail("primitive", e.what());
      }
      if (s.has("vertices")) st.vertices = parse_matrix(s, "vertices").transpose();  // one row per vertex
      if (s.has("faces")) {
        for (const auto& face : s.required("faces")) {
          std::vector<int> f;
          for (const auto& c : face) {
            if (!c.is_number_integer()) s.fail("faces", "expected lists of vertex indices");
            f.push_back(c.get<int>());
          }
          st.faces.push_back(f);
        }
      }
    } else {
      s.allow_only({"name"});
    }
    st.name = s.string_or("name", std::to_string(i));
    if (!index.emplace(st.name, int(i)).second) s.fail("name", "\"" + st.name + "\" names two states");
    a.states.push_back(st);
  }
  a.transitions.resize(a.states.size());
  auto state_of = [&](const JsonObject& t, const char* key) {
    const nlohmann::json& v = t.required(key);
    if (v.is_string()) {
      auto it = index.find(v.get<std::string>());
      if (it == index.end()) t.fail(key, "no state is named \"" + v.get<std::string>() + "\"");
      return it->second;
    }
    if (!v.is_number_integer() || v.get<int>() < 0 || size_t(v.get<int>()) >= a.states.size())
      t.fail(key, "expected a state name or index");
    return v.get<int>();
  };
  const nlohmann::json& transitions = o.required("transitions");
  if (!transitions.is_array()) o.fail("transitions", "expected a list of transitions");
  int max_symbol = -1;
  for (size_t i = 0; i < transitions.size(); ++i) {
    JsonObject t(transitions[i], o.file(), o.path_of("transitions[" + std::to_string(i) + "]"));
    t.allow_only(with_matrices ? std::vector<std::string>{"from", "symbol", "to", "matrix"}
                               : std::vector<std::string>{"from", "symbol", "to"});
    Transition tr;
    int from = state_of(t, "from");
    tr.target = state_of(t, "to");
    tr.symbol = parse_int(t, "symbol");
    if (tr.symbol < 0) t.fail("symbol", "expected a symbol >= 0");
    max_symbol = std::max(max_symbol, tr.symbol);
    if (with_matrices) tr.matrix = parse_matrix(t, "matrix");
    auto& list = a.transitions[size_t(from)];
    for (const Transition& other : list)
      if (other.symbol == tr.symbol) t.fail("symbol", "state already has a transition on this symbol");
    list.push_back(tr);
  }
  for (auto& list : a.transitions)
    std::sort(list.begin(), list.end(), [](const Transition& x, const Transition& y) { return x.symbol < y.symbol; });
  a.alphabet_size = int(o.unsigned_integer_or("alphabet_size", uint64_t(max_symbol + 1)));
  if (o.has("initial")) a.initial = state_of(o, "initial");
  try {
    if (with_matrices) {
      validate(a);
      complete_primitives(a);
    }
  } catch (const InvalidInput& e) {
    o.fail("", e.what());
  }
  return a;
}

Eigen::MatrixXd parse_points(const JsonObject& o, const char* key, bool& rational) {
  const nlohmann::json& v = o.required(key);
  if (!v.is_array() || v.empty()) o.fail(key, "expected a list of [x, y, z] or [x, y, z, w] points");
  std::vector<nlohmann::json> flat;
  for (const auto& item : v) {
    if (item.is_array() && !item.empty() && item[0].is_array())
      for (const auto& p : item) flat.push_back(p);  // a list of rows (products, surfaces)
    else
      flat.push_back(item);
  }
  const size_t dims = flat[0].is_array() ? flat[0].size() : 0;
  if (dims != 3 && dims != 4) o.fail(key, "expected points of 3 coordinates, or 4 with a weight");
  rational = dims == 4;
  Eigen::MatrixXd p(4, Eigen::Index(flat.size()));
  for (size_t i = 0; i < flat.size(); ++i) {
    if (!flat[i].is_array() || flat[i].size() != dims) o.fail(key, "every point needs " + std::to_string(dims) + " numbers");
    for (size_t c = 0; c < dims; ++c) {
      if (!flat[i][c].is_number() || !std::isfinite(flat[i][c].get<double>())) o.fail(key, "expected finite numbers");
      p(Eigen::Index(c), Eigen::Index(i)) = flat[i][c].get<double>();
    }
    if (rational) {
      if (!(p(3, Eigen::Index(i)) > 0)) o.fail(key, "weights must be positive");
      p.block<3, 1>(0, Eigen::Index(i)) *= p(3, Eigen::Index(i));  // homogeneous (w x, w y, w z, w)
    } else {
      p(3, Eigen::Index(i)) = 1;
    }
  }
  return rational ? p : Eigen::MatrixXd(p.topRows(3));
}

NurbsAutomaton parse_nurbs(const JsonObject& o) {
  o.allow_only({"degree", "knots"});
  try {
    return nurbs_automaton(parse_int(o, "degree"), parse_numbers(o, "knots"));
  } catch (const InvalidInput& e) {
    o.fail("", e.what());
  }
}

// Systems nested in systems ("product", "restrict", "library") at most this deep.
constexpr int kMaxSystemDepth = 16;

Cifs parse_system_at(const nlohmann::json& value, const std::string& file, const std::string& path, int depth);

// A side of a junction: a tensor surface ("product" of two curves or "nurbs_surface") with its factors
// kept apart, and its control net.
TensorSurface parse_tensor_surface(const JsonObject& parent, const char* key, int depth) {
  const nlohmann::json& value = parent.required(key);
  if (!value.is_object() || !(value.contains("product") || value.contains("nurbs_surface")))
    parent.fail(key, "expected a tensor surface: an object with \"product\" (two curves) or \"nurbs_surface\"");
  JsonObject o(value, parent.file(), parent.path_of(key));
  TensorSurface out;
  if (o.has("product")) {
    const nlohmann::json& pair = o.required("product");
    if (!pair.is_array() || pair.size() != 2) o.fail("product", "expected a list of two systems");
    out.u = parse_system_at(pair[0], o.file(), o.path_of("product[0]"), depth + 1).automaton;
    out.v = parse_system_at(pair[1], o.file(), o.path_of("product[1]"), depth + 1).automaton;
  } else {
    JsonObject s = o.object("nurbs_surface");
    s.allow_only({"u", "v"});
    out.u = parse_nurbs(s.object("u")).automaton;
    out.v = parse_nurbs(s.object("v")).automaton;
  }
  const Cifs whole = parse_system_at(value, parent.file(), parent.path_of(key), depth + 1);
  if (whole.rational) parent.fail(key, "a junction's sides must be non-rational (weights 1)");
  out.control_points = whole.control_points;
  return out;
}

Cifs parse_system_at(const nlohmann::json& value, const std::string& file, const std::string& path, int depth) {
  if (depth > kMaxSystemDepth)
    throw InvalidInput(file + ": systems nest deeper than " + std::to_string(kMaxSystemDepth) + " levels (product, restrict)");
  if (value.is_string()) {
    try {
      return library_system(value.get<std::string>());
    } catch (const InvalidInput& e) {
      throw InvalidInput(file + ": " + path + ": " + e.what());
    }
  }
  JsonObject o(value, file, path);
  o.allow_only({"name", "library", "states", "transitions", "initial", "alphabet_size", "nurbs_curve", "nurbs_surface",
                "product", "restrict", "drop_symbols", "pattern", "junction", "control_points_mm", "scale", "translate_mm"});
  const int kinds = o.has("library") + o.has("states") + o.has("nurbs_curve") + o.has("nurbs_surface") +
                    o.has("product") + o.has("restrict") + o.has("junction");
  if (kinds != 1)
    o.fail("", "give exactly one of \"library\", \"states\", \"nurbs_curve\", \"nurbs_surface\", \"product\", \"restrict\", \"junction\"");
  Cifs c;
  bool needs_points = false;
  if (o.has("library")) {
    c = parse_system_at(o.required("library"), file, o.path_of("library"), depth + 1);
  } else if (o.has("states")) {
    c.automaton = parse_automaton(o, true);
    needs_points = true;
  } else if (o.has("nurbs_curve")) {
    c.automaton = parse_nurbs(o.object("nurbs_curve")).automaton;
    needs_points = true;
  } else if (o.has("nurbs_surface")) {
    JsonObject s = o.object("nurbs_surface");
    s.allow_only({"u", "v"});
    c.automaton = tensor_product(parse_nurbs(s.object("u")).automaton, parse_nurbs(s.object("v")).automaton);
    needs_points = true;
  } else if (o.has("junction")) {
    JsonObject j = o.object("junction");
    j.allow_only({"a", "b", "ratio", "amplitude", "sides"});
    const TensorSurface a = parse_tensor_surface(j, "a", depth), b = parse_tensor_surface(j, "b", depth);
    JunctionOptions options;
    options.ratio = j.number_or("ratio", options.ratio);
    if (!(options.ratio > 0 && options.ratio < 0.5)) j.fail("ratio", "expected a number strictly between 0 and 0.5");
    options.amplitude = j.number_or("amplitude", options.amplitude);
    if (!(options.amplitude >= 0) || !std::isfinite(options.amplitude)) j.fail("amplitude", "expected a finite number >= 0");
    options.sides = j.boolean_or("sides", false);
    try {
      c = junction(a, b, options);
    } catch (const InvalidInput& e) {
      o.fail("junction", e.what());
    }
  } else if (o.has("product")) {
    const nlohmann::json& pair = o.required("product");
    if (!pair.is_array() || pair.size() != 2) o.fail("product", "expected a list of two systems");
    Cifs a = parse_system_at(pair[0], file, o.path_of("product[0]"), depth + 1);
    Cifs b = parse_system_at(pair[1], file, o.path_of("product[1]"), depth + 1);
    if (a.rational || b.rational) o.fail("product", "rational factors: give the product's control points instead");
    try {
      c.automaton = tensor_product(a.automaton, b.automaton);
    } catch (const InvalidInput& e) {
      o.fail("product", e.what());
    }
    // Default placement a(u) + b(v): point (i, j) = a_i + b_j (a translational surface).
    c.control_points.resize(3, a.control_points.cols() * b.control_points.cols());
    for (Eigen::Index i = 0; i < a.control_points.cols(); ++i)
      for (Eigen::Index j = 0; j < b.control_points.cols(); ++j)
        c.control_points.col(i * b.control_points.cols() + j) = a.control_points.col(i) + b.control_points.col(j);
  } else {
    Cifs inner = parse_system_at(o.required("restrict"), file, o.path_of("restrict"), depth + 1);
    Automaton pattern;
    if (o.has("drop_symbols") == o.has("pattern")) o.fail("", "give either \"drop_symbols\" or \"pattern\" with \"restrict\"");
    if (o.has("drop_symbols")) {
      State only;
      only.name = "pattern";
      pattern.states = {only};
      pattern.transitions.resize(1);
      pattern.alphabet_size = inner.automaton.alphabet_size;
      std::vector<double> drop = parse_numbers(o, "drop_symbols");
      for (int sym = 0; sym < pattern.alphabet_size; ++sym)
        if (std::find(drop.begin(), drop.end(), double(sym)) == drop.end())
          pattern.transitions[0].push_back(Transition{sym, 0, Eigen::MatrixXd()});
    } else {
      pattern = parse_automaton(o.object("pattern"), false);
    }
    try {
      c.automaton = restrict_words(inner.automaton, pattern);
    } catch (const InvalidInput& e) {
      o.fail("", e.what());
    }
    c.control_points = inner.control_points;
    c.rational = inner.rational;
  }
  c.name = o.string_or("name", c.name.empty() ? (o.has("library") ? o.required("library").dump() : "system") : c.name);
  if (o.has("control_points_mm")) {
    c.control_points = parse_points(o, "control_points_mm", c.rational);
  } else if (needs_points) {
    o.fail("control_points_mm", "missing (required for this system)");
  }
  double scale = o.has("scale") ? o.positive_length("scale") : 1.0;
  Vec3d shift = o.vec3_or("translate_mm", Vec3d{});
  for (Eigen::Index i = 0; i < c.control_points.cols(); ++i) {
    double w = c.rational ? c.control_points(3, i) : 1.0;
    c.control_points.block<3, 1>(0, i) = c.control_points.block<3, 1>(0, i) * scale + Eigen::Vector3d(shift.x, shift.y, shift.z) * w;
  }
  try {
    validate(c);
  } catch (const InvalidInput& e) {
    o.fail("", e.what());
  }
  return c;
}

}  // namespace

Cifs parse_system(const nlohmann::json& value, const std::string& file, const std::string& path) {
  return parse_system_at(value, file, path, 0);
}

Cifs load_system(const std::string& name_or_file) {
  std::error_code ec;
  if (!std::filesystem::exists(name_or_file, ec)) {
    if (name_or_file.size() > 5 && name_or_file.substr(name_or_file.size() - 5) == ".json")
      throw IoError(name_or_file + ": cannot open the system file");
    return library_system(name_or_file);
  }
  return parse_system(read_json_file(name_or_file, "a system file (.json)"), name_or_file, "");
}

namespace {

// A barycentric point of the initial state's space, in mm (rational systems: homogeneous divided).
Eigen::Vector3d space_point(const Cifs& c, const Eigen::VectorXd& x) {
  const Eigen::VectorXd h = c.control_points * x;
  return c.rational ? Eigen::Vector3d(h.head<3>() / h(3)) : Eigen::Vector3d(h.head<3>());
}

// The unit direction in space of a barycentric direction d at the point x (the projection's
// derivative for rational systems).
Eigen::Vector3d space_direction(const Cifs& c, const Eigen::VectorXd& x, const Eigen::VectorXd& d) {
  const Eigen::VectorXd h = c.control_points * x, dh = c.control_points * d;
  Eigen::Vector3d v = c.rational ? Eigen::Vector3d(dh.head<3>() / h(3) - h.head<3>() * dh(3) / (h(3) * h(3)))
                                 : Eigen::Vector3d(dh.head<3>());
  return v.norm() > 0 ? Eigen::Vector3d(v / v.norm()) : v;
}

std::vector<double> as_list(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

}  // namespace

nlohmann::json initial_frames_json(const Cifs& c) {
  const Automaton& a = c.automaton;
  const State& s = a.states[size_t(a.initial)];
  const int dimension = primitive_dimension(s.primitive);
  nlohmann::json frames = nlohmann::json::array();
  if (dimension < 1 || dimension > 2 || s.vertices.cols() == 0) return frames;
  // Orientation: into the primitive, towards the mean of its vertices.
  const Eigen::VectorXd inside = s.vertices.rowwise().mean();
  for (const Transition& t : a.transitions[size_t(a.initial)]) {
    nlohmann::json f = {{"symbol", t.symbol}};
    try {
      const FixedPointFrame frame = limit_frame(a, a.initial, t.symbol, dimension, inside);
      f["point_mm"] = as_list(space_point(c, frame.point));
      f["smooth"] = frame.smooth;
      if (!frame.smooth) {
        f["reason"] = frame.reason;
      } else {
        nlohmann::json tangents = nlohmann::json::array();
        std::vector<Eigen::Vector3d> directions;
        for (const Eigen::VectorXd& d : frame.directions) {
          directions.push_back(space_direction(c, frame.point, d));
          tangents.push_back(as_list(directions.back()));
        }
        f["tangents"] = tangents;
        f["rates"] = frame.rates;
        if (dimension == 2) {
          const Eigen::Vector3d n = directions[0].cross(directions[1]);
          f["normal"] = as_list(n.norm() > 0 ? Eigen::Vector3d(n / n.norm()) : n);
        }
      }
    } catch (const InvalidInput& e) {
      f["smooth"] = false;
      f["reason"] = e.what();
    }
    frames.push_back(f);
  }
  return frames;
}

nlohmann::json system_json(const Cifs& c) {
  const Automaton& a = c.automaton;
  auto matrix = [](const Eigen::MatrixXd& m) {
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      nlohmann::json row = nlohmann::json::array();
      for (Eigen::Index j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
      rows.push_back(row);
    }
    return rows;
  };
  std::vector<int> stationary = stationary_states(a);
  nlohmann::json states = nlohmann::json::array();
  for (size_t q = 0; q < a.states.size(); ++q) {
    const State& s = a.states[q];
    nlohmann::json fixed = nlohmann::json::array();
    for (const Transition& t : a.transitions[q])
      if (t.target == int(q)) {
        try {
          Eigen::VectorXd x = fixed_point(t.matrix);
          fixed.push_back({{"symbol", t.symbol}, {"barycentric", std::vector<double>(x.data(), x.data() + x.size())}});
        } catch (const InvalidInput&) {
          fixed.push_back({{"symbol", t.symbol}, {"barycentric", nullptr}});
        }
      }
    states.push_back({{"index", q},
                      {"name", s.name},
                      {"control_points", s.control_points},
                      {"primitive", primitive_name(s.primitive)},
                      {"stationary", std::find(stationary.begin(), stationary.end(), int(q)) != stationary.end()},
                      {"fixed_points", fixed},
                      {"vertices", matrix(s.vertices.transpose())}});
  }
  nlohmann::json transitions = nlohmann::json::array();
  for (size_t q = 0; q < a.states.size(); ++q)
    for (const Transition& t : a.transitions[q])
      transitions.push_back({{"from", q}, {"symbol", t.symbol}, {"to", t.target}, {"matrix", matrix(t.matrix)}});
  nlohmann::json points = nlohmann::json::array();
  for (Eigen::Index i = 0; i < c.control_points.cols(); ++i) {
    if (c.rational) {
      double w = c.control_points(3, i);
      points.push_back({c.control_points(0, i) / w, c.control_points(1, i) / w, c.control_points(2, i) / w, w});
    } else {
      points.push_back({c.control_points(0, i), c.control_points(1, i), c.control_points(2, i)});
    }
  }
  return {{"name", c.name},
          {"alphabet_size", a.alphabet_size},
          {"initial", a.initial},
          {"rational", c.rational},
          {"states", states},
          {"transitions", transitions},
          {"control_points_mm", points},
          {"limit_frames", initial_frames_json(c)}};
}

}  // namespace cifs
}  // namespace lacuna
