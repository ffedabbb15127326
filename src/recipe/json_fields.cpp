#include "recipe/json_fields.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "errors.h"
#include "util/suggest.h"
#include "util/system.h"

namespace lacuna {
namespace {

std::string short_value(const nlohmann::json& value) {
  std::string text = value.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

}  // namespace

std::string describe_json_type(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null: return "null";
    case nlohmann::json::value_t::object: return "an object";
    case nlohmann::json::value_t::array: return "an array";
    case nlohmann::json::value_t::string: return "a string";
    case nlohmann::json::value_t::boolean: return "a boolean";
    default: return "a number";
  }
}

nlohmann::json parse_json_text(const std::string& text, const std::string& file) {
  // Duplicate keys are almost always a mistake; nlohmann keeps the last one silently.
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  auto callback = [&](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    switch (event) {
      case nlohmann::json::parse_event_t::object_start:
      case nlohmann::json::parse_event_t::array_start:
        // Checked while parsing: what reads the value later recurses into it.
        if (depth >= kMaxJsonDepth)
          throw InvalidInput(file + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
        if (event == nlohmann::json::parse_event_t::object_start) keys.emplace_back();
        break;
      case nlohmann::json::parse_event_t::object_end:
        if (!keys.empty()) keys.pop_back();
        break;
      case nlohmann::json::parse_event_t::key:
        if (!keys.empty() && !keys.back().insert(parsed.get<std::string>()).second && duplicate.empty())
          duplicate = parsed.get<std::string>();
        break;
      default:
        break;
    }
    return true;
  };
  nlohmann::json value;
  try {
    value = nlohmann::json::parse(text, callback, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const nlohmann::json::exception& e) {
    // Drop nlohmann's "[json.exception.parse_error.101] " prefix; keep the line and column.
    std::string what = e.what();
    auto bracket = what.find("] ");
    throw InvalidInput(file + ": not valid JSON: " + (bracket == std::string::npos ? what : what.substr(bracket + 2)));
  }
  if (!duplicate.empty()) throw InvalidInput(file + ": key \"" + duplicate + "\" appears twice in the same object");
  return value;
}

nlohmann::json read_json_file(const std::string& path, const std::string& what) {
  return parse_json_text(read_text_file(path, what, kMaxJsonFileBytes), path);
}

JsonObject::JsonObject(const nlohmann::json& value, std::string file, std::string path)
    : value_(value), file_(std::move(file)), path_(std::move(path)) {
  if (!value_.is_object())
    throw InvalidInput(file_ + ": " + (path_.empty() ? std::string("top level") : path_) +
                       ": expected an object, got " + describe_json_type(value_));
}

std::string JsonObject::path_of(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

void JsonObject::fail(const std::string& key, const std::string& message) const {
  std::string where = key.empty() ? (path_.empty() ? std::string("top level") : path_) : path_of(key);
  throw InvalidInput(file_ + ": " + where + ": " + message);
}

void JsonObject::allow_only(std::initializer_list<const char*> allowed) const {
  allow_only(std::vector<std::string>(allowed.begin(), allowed.end()));
}

void JsonObject::allow_only(const std::vector<std::string>& allowed) const {
  for (auto it = value_.begin(); it != value_.end(); ++it) {
    if (std::find(allowed.begin(), allowed.end(), it.key()) != allowed.end()) continue;
    const std::string hint = did_you_mean(it.key(), allowed);
    std::string message = "unknown key \"" + it.key() + "\"" + hint;
    if (hint.empty()) {
      message += "; expected one of:";
      for (const std::string& a : allowed) message += " " + a;
    }
    fail("", message);
  }
}

const nlohmann::json& JsonObject::required(const char* key) const {
  auto it = value_.find(key);
  if (it == value_.end()) fail(key, "missing (required)");
  return *it;
}

std::string JsonObject::string(const char* key) const {
  const nlohmann::json& v = required(key);
  if (!v.is_string()) fail(key, "expected a string, got " + describe_json_type(v));
  // C file and XML interfaces would cut the text at a NUL and use what is before it.
  if (v.get_ref<const std::string&>().find('\0') != std::string::npos) fail(key, "a string may not hold a NUL character");
  return v.get<std::string>();
}

std::string JsonObject::string_or(const char* key, const std::string& fallback) const {
  return has(key) ? string(key) : fallback;
}

double JsonObject::number(const char* key) const {
  const nlohmann::json& v = required(key);
  if (!v.is_number()) fail(key, "expected a number, got " + describe_json_type(v) + " " + short_value(v));
  double d = v.get<double>();
  if (!std::isfinite(d)) fail(key, "expected a finite number");
  return d;
}

double JsonObject::number_or(const char* key, double fallback) const { return has(key) ? number(key) : fallback; }

double JsonObject::positive_length(const char* key) const {
  const nlohmann::json& v = required(key);
  if (!v.is_number()) fail(key, "expected a positive length in mm, got " + describe_json_type(v) + " " + short_value(v));
  double d = v.get<double>();
  if (!(d > 0) || !std::isfinite(d)) fail(key, "expected a positive length in mm, got " + short_value(v));
  return d;
}

double JsonObject::positive_length_or(const char* key, double fallback) const {
  return has(key) ? positive_length(key) : fallback;
}

uint64_t JsonObject::unsigned_integer_or(const char* key, uint64_t fallback) const {
  if (!has(key)) return fallback;
  const nlohmann::json& v = value_.at(key);
  if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0))
    fail(key, "expected a non-negative integer, got " + short_value(v));
  return v.get<uint64_t>();
}

bool JsonObject::boolean_or(const char* key, bool fallback) const {
  if (!has(key)) return fallback;
  const nlohmann::json& v = value_.at(key);
  if (!v.is_boolean()) fail(key, "expected true or false, got " + short_value(v));
  return v.get<bool>();
}

namespace {
Vec3d to_vec3(const nlohmann::json& v, const JsonObject& where, const std::string& key) {
  if (!v.is_array() || v.size() != 3) where.fail(key, "expected [x, y, z], got " + short_value(v));
  Vec3d out;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number()) where.fail(key, "expected [x, y, z] of numbers, got " + short_value(v));
    out[i] = v[i].get<double>();
    if (!std::isfinite(out[i])) where.fail(key, "coordinates must be finite");
  }
  return out;
}
}  // namespace

Vec3d JsonObject::vec3(const char* key) const { return to_vec3(required(key), *this, key); }

Vec3d JsonObject::vec3_or(const char* key, const Vec3d& fallback) const { return has(key) ? vec3(key) : fallback; }

Vec3d JsonObject::direction_or(const char* key, const Vec3d& fallback) const {
  Vec3d d = vec3_or(key, fallback);
  double n = norm(d);
  if (!(n > 0)) fail(key, "expected a non-zero direction vector");
  return d / n;
}

std::vector<Vec3d> JsonObject::vec3_list(const char* key) const {
  const nlohmann::json& v = required(key);
  if (!v.is_array()) fail(key, "expected a list of [x, y, z] points, got " + describe_json_type(v));
  std::vector<Vec3d> out;
  out.reserve(v.size());
  for (size_t i = 0; i < v.size(); ++i) out.push_back(to_vec3(v[i], *this, std::string(key) + "[" + std::to_string(i) + "]"));
  return out;
}

std::vector<Vec2d> JsonObject::vec2_list(const nlohmann::json& v, const std::string& key) const {
  if (!v.is_array()) fail(key, "expected a list of [x, y] points, got " + describe_json_type(v));
  std::vector<Vec2d> out;
  out.reserve(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    const nlohmann::json& p = v[i];
    std::string where = key + "[" + std::to_string(i) + "]";
    if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
      fail(where, "expected [x, y], got " + short_value(p));
    Vec2d q{p[0].get<double>(), p[1].get<double>()};
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) fail(where, "coordinates must be finite");
    out.push_back(q);
  }
  return out;
}

std::vector<double> JsonObject::positive_length_list(const char* key) const {
  const nlohmann::json& v = required(key);
  if (!v.is_array()) fail(key, "expected a list of positive lengths in mm, got " + describe_json_type(v));
  std::vector<double> out;
  for (size_t i = 0; i < v.size(); ++i) {
    if (!v[i].is_number() || !(v[i].get<double>() > 0) || !std::isfinite(v[i].get<double>()))
      fail(std::string(key) + "[" + std::to_string(i) + "]", "expected a positive length in mm, got " + short_value(v[i]));
    out.push_back(v[i].get<double>());
  }
  return out;
}

JsonObject JsonObject::object(const char* key) const { return JsonObject(required(key), file_, path_of(key)); }

}  // namespace lacuna
