// Reading typed fields out of recipe JSON with errors that name the file, the JSON path and what
// was expected, and "did you mean" suggestions for misspelled keys.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry.h"

namespace lacuna {

// The largest JSON file read (recipes, systems, control points): larger geometry goes in mesh files.
constexpr uint64_t kMaxJsonFileBytes = uint64_t{256} << 20;
// The deepest nesting of JSON arrays and objects read; deeper documents are refused before they are
// built (a recipe needs about 10 levels, a system of 16 nested products about 40).
constexpr int kMaxJsonDepth = 64;

// Parses JSON text (comments allowed) and rejects duplicate keys and nesting deeper than
// kMaxJsonDepth. Throws InvalidInput with the file, line and column on syntax errors.
nlohmann::json parse_json_text(const std::string& text, const std::string& file);

// Reads and parses the JSON file at `path` (`what` names it in messages: "the recipe file"). Throws
// IoError for a missing or unreadable file, a folder, a pipe or a device, InvalidInput for a file
// over kMaxJsonFileBytes (before reading it) and for what parse_json_text() refuses.
nlohmann::json read_json_file(const std::string& path, const std::string& what);

// One JSON object in a recipe, with its path for messages ("inputs.ball").
class JsonObject {
 public:
  // Throws InvalidInput unless `value` is an object.
  JsonObject(const nlohmann::json& value, std::string file, std::string path);

  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  const nlohmann::json& json() const { return value_; }
  bool has(const char* key) const { return value_.contains(key); }

  // Throws InvalidInput for any key not in `allowed`, suggesting the closest allowed key.
  void allow_only(std::initializer_list<const char*> allowed) const;
  void allow_only(const std::vector<std::string>& allowed) const;

  // The path of a key below this object, for messages.
  std::string path_of(const std::string& key) const;
  // Throws InvalidInput "<file>: <path.key>: <message>".
  [[noreturn]] void fail(const std::string& key, const std::string& message) const;

  const nlohmann::json& required(const char* key) const;

  std::string string(const char* key) const;
  std::string string_or(const char* key, const std::string& fallback) const;
  double number(const char* key) const;
  double number_or(const char* key, double fallback) const;
  // A length in mm that must be > 0 (or >= 0 when `allow_zero`).
  double positive_length(const char* key) const;
  double positive_length_or(const char* key, double fallback) const;
  uint64_t unsigned_integer_or(const char* key, uint64_t fallback) const;
  bool boolean_or(const char* key, bool fallback) const;
  Vec3d vec3(const char* key) const;
  Vec3d vec3_or(const char* key, const Vec3d& fallback) const;
  // A non-zero direction, normalized.
  Vec3d direction_or(const char* key, const Vec3d& fallback) const;
  std::vector<Vec3d> vec3_list(const char* key) const;
  std::vector<Vec2d> vec2_list(const nlohmann::json& value, const std::string& path) const;
  std::vector<double> positive_length_list(const char* key) const;
  JsonObject object(const char* key) const;

 private:
  const nlohmann::json& value_;
  std::string file_;
  std::string path_;
};

// A short description of a JSON value's type for messages ("a string", "an array").
std::string describe_json_type(const nlohmann::json& value);

}  // namespace lacuna
