#include "fill/motif_file.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "errors.h"
#include "util/system.h"

namespace lacuna {
namespace fill {
namespace {

constexpr uint64_t kMaxMotifFileBytes = 16u << 20;
constexpr size_t kMaxOutlinePoints = 1'000'000;

std::string lower_extension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string e = path.substr(dot);
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

std::vector<Vec2d> json_outline(const std::string& text, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InvalidInput(path + ": not JSON (" + e.what() + ")");
  }
  const std::string where = j.is_object() ? path + ": polygon" : path;
  if (j.is_object()) {
    if (!j.contains("polygon") || j.size() != 1) throw InvalidInput(path + ": expected {\"polygon\": [[x, y], ...]} or a list of points");
    j = j["polygon"];
  }
  if (!j.is_array()) throw InvalidInput(where + ": expected a list of [x, y] points");
  if (j.size() > kMaxOutlinePoints) throw InvalidInput(where + ": more than 1 000 000 points");
  std::vector<Vec2d> points;
  for (size_t i = 0; i < j.size(); ++i) {
    const nlohmann::json& p = j[i];
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
      throw InvalidInput(where + "[" + std::to_string(i) + "]: expected [x, y] (two numbers)");
    points.push_back({p[0].get<double>(), p[1].get<double>()});
  }
  return points;
}

// The value of the first d="..." (or d='...') attribute of the first <path ...> element.
std::string first_path_data(const std::string& svg, const std::string& path) {
  size_t at = 0;
  while ((at = svg.find("<path", at)) != std::string::npos) {
    const size_t end = svg.find('>', at);
    if (end == std::string::npos) break;
    const std::string element = svg.substr(at, end - at);
    for (size_t k = element.find("d"); k != std::string::npos; k = element.find("d", k + 1)) {
      // The attribute name "d" alone: preceded by white space, followed by optional spaces and '='.
      if (k == 0 || !std::isspace(static_cast<unsigned char>(element[k - 1]))) continue;
      size_t q = k + 1;
      while (q < element.size() && std::isspace(static_cast<unsigned char>(element[q]))) ++q;
      if (q >= element.size() || element[q] != '=') continue;
      ++q;
      while (q < element.size() && std::isspace(static_cast<unsigned char>(element[q]))) ++q;
      if (q >= element.size() || (element[q] != '"' && element[q] != '\'')) continue;
      const size_t close = element.find(element[q], q + 1);
      if (close == std::string::npos) break;
      return element.substr(q + 1, close - q - 1);
    }
    at = end;
  }
  throw InvalidInput(path + ": no <path> element with a \"d\" attribute");
}

}  // namespace

std::vector<Vec2d> svg_path_points(const std::string& d, const std::string& where) {
  std::vector<Vec2d> points;
  size_t i = 0;
  char command = 0;
  bool closed = false;
  Vec2d current{0, 0};
  auto skip = [&] {
    while (i < d.size() && (std::isspace(static_cast<unsigned char>(d[i])) || d[i] == ',')) ++i;
  };
  auto fail = [&](const std::string& what) -> void {
    throw InvalidInput(where + ": path data at character " + std::to_string(i + 1) + ": " + what);
  };
  auto number = [&]() {
    skip();
    const char* begin = d.c_str() + i;
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (end == begin || !std::isfinite(v)) fail("expected a number");
    i += size_t(end - begin);
    return v;
  };
  auto starts_number = [&] {
    skip();
    return i < d.size() && (std::isdigit(static_cast<unsigned char>(d[i])) || d[i] == '-' || d[i] == '+' || d[i] == '.');
  };
  for (skip(); i < d.size(); skip()) {
    if (std::isalpha(static_cast<unsigned char>(d[i]))) {
      command = d[i];
      const char upper = char(std::toupper(static_cast<unsigned char>(command)));
      if (upper == 'C' || upper == 'S' || upper == 'Q' || upper == 'T' || upper == 'A')
        fail(std::string("command '") + command + "' draws a curve; a polygon motif takes straight segments only (M, L, H, V, Z)");
      if (upper != 'M' && upper != 'L' && upper != 'H' && upper != 'V' && upper != 'Z')
        fail(std::string("unknown command '") + command + "'");
      ++i;
      if (upper == 'Z') {
        closed = true;
        command = 0;
        continue;
      }
      if (upper == 'M' && !points.empty()) fail("a second sub-path; a motif is one closed outline");
      if (upper != 'M' && points.empty()) fail("expected a move-to (M or m) first");
    } else if (command == 0) {
      fail(points.empty() ? "expected a move-to (M or m) first" : "expected a command");
    }
    if (closed) fail("points after the path was closed (Z); a motif is one closed outline");
    if (!starts_number()) fail(std::string("expected coordinates after '") + command + "'");
    const bool relative = std::islower(static_cast<unsigned char>(command));
    const char upper = char(std::toupper(static_cast<unsigned char>(command)));
    Vec2d next = current;
    if (upper == 'H') {
      next.x = number() + (relative ? current.x : 0);
    } else if (upper == 'V') {
      next.y = number() + (relative ? current.y : 0);
    } else {
      const double x = number(), y = number();
      next = relative ? Vec2d{current.x + x, current.y + y} : Vec2d{x, y};
    }
    if (points.size() >= kMaxOutlinePoints) fail("more than 1 000 000 points");
    points.push_back(next);
    current = next;
    if (upper == 'M') command = relative ? 'l' : 'L';  // further pairs are line-tos
  }
  if (points.empty()) throw InvalidInput(where + ": the path has no points");
  // A closing point equal to the first is the same corner.
  if (points.size() > 1 && points.back().x == points.front().x && points.back().y == points.front().y) points.pop_back();
  return points;
}

bool names_motif_file(const std::string& name) {
  const std::string extension = lower_extension(name);
  return extension == ".json" || extension == ".svg";
}

Motif2 motif_from_file(const std::string& path) { return polygon_motif(read_motif_outline(path)); }

std::vector<Vec2d> read_motif_outline(const std::string& path) {
  if (!names_motif_file(path))
    throw InvalidInput(path + ": expected a .json (a list of [x, y] points) or .svg (a path) motif file");
  const std::string text = read_text_file(path, "the motif file", kMaxMotifFileBytes);
  if (lower_extension(path) == ".json") return json_outline(text, path);
  std::vector<Vec2d> points = svg_path_points(first_path_data(text, path), path);
  for (Vec2d& p : points) p.y = -p.y;  // SVG's y axis points down
  return points;
}

}  // namespace fill
}  // namespace lacuna
