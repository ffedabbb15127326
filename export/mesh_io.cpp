#include "export/mesh_io.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>
#include <string_view>

#include "errors.h"

namespace lacuna {

// Defined in threemf.cpp and draco.cpp; read_mesh has already checked that the file exists and is
// not empty.
TriMesh read_3mf(const std::string& path, const ReadOptions& options);
TriMesh read_draco(const std::string& path, const ReadOptions& options);

namespace {

constexpr size_t kIoChunkBytes = 64 * 1024;
constexpr size_t kMaxLineBytes = 16 << 20;
constexpr uint64_t kStlHeaderBytes = 84;
constexpr uint64_t kStlRecordBytes = 50;
constexpr double kVertexBytes = sizeof(Vec3d);
constexpr double kTriangleBytes = sizeof(std::array<uint32_t, 3>);
// A welded STL vertex also holds its key (12 bytes) and up to four 4-byte hash slots while reading.
constexpr double kWeldedVertexBytes = kVertexBytes + 12 + 16;
constexpr uint64_t kMaxVertices = std::numeric_limits<uint32_t>::max();

// Concatenates the arguments as an ostream would print them.
template <typename... Args>
std::string cat(const Args&... args) {
  std::ostringstream out;
  (out << ... << args);
  return out.str();
}

// Throws InvalidInput("<path>: <what>").
[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InvalidInput(path + ": " + what);
}

// A byte count in GiB, for ResourceLimit messages.
std::string gib(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f GiB", bytes / double(uint64_t{1} << 30));
  return text;
}

// Throws ResourceLimit if `bytes` (an estimate for what the mesh needs) exceeds the budget;
// `what()` describes the contents (built only then, as this runs once per line of text files).
template <typename What>
void check_memory(const std::string& path, double bytes, const ReadOptions& options, What what) {
  if (bytes > double(options.max_memory_bytes)) {
    throw ResourceLimit(cat(path, ": ", what(), " need about ", gib(bytes),
                            ", more than the memory limit of ",
                            gib(double(options.max_memory_bytes))));
  }
}

// Whitespace within a line (line breaks are handled by the line reader).
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// A short, printable excerpt of a line for error messages.
std::string excerpt(std::string_view line) {
  constexpr size_t kMaxChars = 60;
  while (!line.empty() && (is_space(line.front()) || line.front() == '\n')) line.remove_prefix(1);
  while (!line.empty() && is_space(line.back())) line.remove_suffix(1);
  std::string out;
  for (char c : line.substr(0, kMaxChars)) out += (c >= 32 && c < 127) ? c : '?';
  if (line.size() > kMaxChars) out += "...";
  return out;
}

// Splits a line into whitespace-separated tokens (views into `line`).
void split(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    size_t start = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
}

// ASCII case-insensitive equality.
bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

// Parses the whole token as a double (locale-independent); false if it is not one.
bool parse_double(std::string_view text, double& value) {
  // from_chars rejects a leading '+', which some exporters write.
  if (text.size() > 1 && text[0] == '+' && text[1] != '-') text.remove_prefix(1);
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

// Parses the whole token as a signed 64-bit integer.
bool parse_int(std::string_view text, int64_t& value) {
  if (text.size() > 1 && text[0] == '+' && text[1] != '-') text.remove_prefix(1);
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

// Parses the whole token as an unsigned 64-bit integer.
bool parse_uint(std::string_view text, uint64_t& value) {
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size();
}

// Little-endian loads and stores, independent of the host byte order.
uint32_t load_le32(const unsigned char* p) {
  return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24;
}

float load_le_float(const unsigned char* p) {
  uint32_t bits = load_le32(p);
  float value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

void store_le32(uint32_t value, unsigned char* p) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<unsigned char>(value >> (8 * i));
}

void store_le_float(float value, unsigned char* p) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  store_le32(bits, p);
}

// The size of a regular file; throws IoError if it is missing, unreadable or not a regular file.
uint64_t regular_file_size(const std::string& path) {
  struct stat info;
  if (::stat(path.c_str(), &info) != 0) {
    throw IoError(cat("cannot open '", path, "': ", std::strerror(errno)));
  }
  if (S_ISDIR(info.st_mode)) throw IoError(cat("cannot read '", path, "': it is a directory"));
  if (!S_ISREG(info.st_mode)) throw IoError(cat("cannot read '", path, "': not a regular file"));
  return static_cast<uint64_t>(info.st_size);
}

// A buffered reader that tracks the byte offset and line number for error messages.
class InputFile {
 public:
  explicit InputFile(const std::string& path) : path_(path), buffer_(kIoChunkBytes) {
    size_ = regular_file_size(path);
    file_ = std::fopen(path.c_str(), "rb");
    if (!file_) throw IoError(cat("cannot open '", path, "': ", std::strerror(errno)));
  }
  ~InputFile() { std::fclose(file_); }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  const std::string& path() const { return path_; }
  uint64_t size() const { return size_; }
  uint64_t offset() const { return offset_; }  // bytes consumed so far
  uint64_t line() const { return line_; }      // number of the line read_line returned last

  // Copies up to n bytes and returns how many there were (fewer only at the end of the file).
  size_t read(void* destination, size_t n) {
    auto* out = static_cast<char*>(destination);
    size_t done = 0;
    while (done < n && (pos_ < end_ || fill())) {
      size_t take = std::min(n - done, end_ - pos_);
      std::memcpy(out + done, buffer_.data() + pos_, take);
      pos_ += take;
      done += take;
    }
    offset_ += done;
    return done;
  }

  // Reads the next line without its line break; false at the end of the file.
  bool read_line(std::string& line) {
    line.clear();
    bool any = false;
    for (;;) {
      if (pos_ == end_ && !fill()) {
        if (!any) return false;
        break;
      }
      any = true;
      const char* start = buffer_.data() + pos_;
      const void* newline = std::memchr(start, '\n', end_ - pos_);
      size_t n = newline ? static_cast<const char*>(newline) - start : end_ - pos_;
      if (line.size() + n > kMaxLineBytes) {
        fail(path_, cat("line ", line_ + 1, ": longer than ", kMaxLineBytes, " bytes"));
      }
      line.append(start, n);
      size_t consumed = n + (newline ? 1 : 0);
      pos_ += consumed;
      offset_ += consumed;
      if (newline) break;
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    ++line_;
    return true;
  }

  // Goes back to the start of the file.
  void rewind() {
    if (std::fseek(file_, 0, SEEK_SET) != 0) {
      throw IoError(cat("cannot read '", path_, "': ", std::strerror(errno)));
    }
    pos_ = end_ = 0;
    offset_ = line_ = 0;
  }

 private:
  bool fill() {
    pos_ = 0;
    end_ = std::fread(buffer_.data(), 1, buffer_.size(), file_);
    if (end_ == 0 && std::ferror(file_)) {
      throw IoError(cat("cannot read '", path_, "': ", std::strerror(errno)));
    }
    return end_ > 0;
  }

  std::string path_;
  std::FILE* file_ = nullptr;
  uint64_t size_ = 0;
  std::vector<char> buffer_;
  size_t pos_ = 0, end_ = 0;
  uint64_t offset_ = 0;
  uint64_t line_ = 0;
};

// Gives vertices with bit-identical float coordinates one index, in first-appearance order.
class Welder {
 public:
  explicit Welder(uint64_t expected_vertices) {
    size_t slots = 16;
    while (slots < 2 * expected_vertices) slots *= 2;
    slots_.assign(slots, 0);
    keys_.reserve(expected_vertices);
  }

  // The number of distinct vertices so far.
  size_t size() const { return keys_.size(); }

  // The index of the vertex at (x, y, z), adding it if it is new.
  uint32_t add(float x, float y, float z) {
    std::array<uint32_t, 3> key;
    std::memcpy(&key[0], &x, 4);
    std::memcpy(&key[1], &y, 4);
    std::memcpy(&key[2], &z, 4);
    size_t mask = slots_.size() - 1;
    for (size_t i = hash(key) & mask;; i = (i + 1) & mask) {
      if (slots_[i] == 0) {
        keys_.push_back(key);
        slots_[i] = static_cast<uint32_t>(keys_.size());
        if (2 * keys_.size() > slots_.size()) grow();
        return static_cast<uint32_t>(keys_.size() - 1);
      }
      if (keys_[slots_[i] - 1] == key) return slots_[i] - 1;
    }
  }

  // The distinct vertices, in index order.
  std::vector<Vec3d> positions() const {
    std::vector<Vec3d> out;
    out.reserve(keys_.size());
    for (const auto& key : keys_) {
      float p[3];
      std::memcpy(p, key.data(), sizeof p);
      out.push_back({p[0], p[1], p[2]});
    }
    return out;
  }

 private:
  static uint64_t hash(const std::array<uint32_t, 3>& key) {
    uint64_t h = (uint64_t{key[0]} << 32 | key[1]) * 0x9e3779b97f4a7c15ull ^ key[2];
    h ^= h >> 31;
    h *= 0xbf58476d1ce4e5b9ull;
    return h ^ (h >> 29);
  }

  void grow() {
    std::vector<uint32_t> old;
    old.swap(slots_);
    slots_.assign(old.size() * 2, 0);
    size_t mask = slots_.size() - 1;
    for (uint32_t slot : old) {
      if (slot == 0) continue;
      size_t i = hash(keys_[slot - 1]) & mask;
      while (slots_[i] != 0) i = (i + 1) & mask;
      slots_[i] = slot;
    }
  }

  std::vector<std::array<uint32_t, 3>> keys_;  // float bit patterns, indexed by vertex
  std::vector<uint32_t> slots_;                // vertex index + 1; 0 marks an empty slot
};

// Throws ResourceLimit if the welded vertices so far and `triangles` exceed the budget.
void check_welded_memory(const std::string& path, const Welder& welder, uint64_t triangles,
                         const ReadOptions& options) {
  if (welder.size() >= kMaxVertices) {
    throw ResourceLimit(cat(path, ": more than ", kMaxVertices, " distinct vertices"));
  }
  check_memory(
      path, double(welder.size()) * kWeldedVertexBytes + double(triangles) * kTriangleBytes,
      options, [&] { return cat(welder.size(), " vertices and ", triangles, " triangles"); });
}

// Reads `count` 50-byte records after the 84-byte header, welding the corners.
TriMesh read_binary_stl(InputFile& file, uint64_t count, const ReadOptions& options) {
  const std::string& path = file.path();
  // A closed mesh has about half as many vertices as triangles; the exact count is checked as
  // the welding goes on.
  check_memory(path, double(count) * (kTriangleBytes + kWeldedVertexBytes / 2), options,
               [&] { return cat(count, " triangles"); });
  Welder welder(count / 2);
  TriMesh mesh;
  mesh.triangles.reserve(count);
  constexpr uint64_t kRecordsPerChunk = kIoChunkBytes / kStlRecordBytes;
  std::vector<unsigned char> chunk(kRecordsPerChunk * kStlRecordBytes);
  for (uint64_t first = 0; first < count; first += kRecordsPerChunk) {
    uint64_t records = std::min(kRecordsPerChunk, count - first);
    if (file.read(chunk.data(), records * kStlRecordBytes) != records * kStlRecordBytes) {
      fail(path, cat("binary STL ends inside triangle ", first, " of ", count,
                     " (the file changed while being read?)"));
    }
    for (uint64_t r = 0; r < records; ++r) {
      const unsigned char* record = chunk.data() + r * kStlRecordBytes;
      std::array<uint32_t, 3> triangle;
      for (int v = 0; v < 3; ++v) {
        const unsigned char* p = record + 12 + 12 * v;
        float x = load_le_float(p), y = load_le_float(p + 4), z = load_le_float(p + 8);
        if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
          uint64_t t = first + r;
          fail(path,
               cat("triangle ", t, " (byte offset ", kStlHeaderBytes + t * kStlRecordBytes,
                   "): vertex ", v, " has a non-finite coordinate (", x, " ", y, " ", z, ")"));
        }
        triangle[v] = welder.add(x, y, z);
      }
      mesh.triangles.push_back(triangle);
    }
    check_welded_memory(path, welder, count, options);
  }
  mesh.positions_mm = welder.positions();
  return mesh;
}

// Parses solid / facet / outer loop / vertex x3 / endloop / endfacet / endsolid, one per line.
TriMesh read_ascii_stl(InputFile& file, const ReadOptions& options) {
  const std::string& path = file.path();
  std::string line;
  std::vector<std::string_view> tokens;
  auto next = [&] {
    while (file.read_line(line)) {
      split(line, tokens);
      if (!tokens.empty()) return true;
    }
    tokens.clear();
    return false;
  };
  auto expected = [&](const std::string& what) {
    if (tokens.empty()) {
      fail(path, cat("expected ", what, " but the file ends after line ", file.line()));
    }
    fail(path, cat("line ", file.line(), ": expected ", what, ", got '", excerpt(line), "'"));
  };
  auto is = [&](size_t count, const char* first, const char* second = nullptr) {
    return tokens.size() == count && iequals(tokens[0], first) &&
           (!second || iequals(tokens[1], second));
  };

  if (!next() || !iequals(tokens[0], "solid")) expected("'solid name'");
  Welder welder(0);
  TriMesh mesh;
  for (;;) {
    if (!next()) expected("'facet normal nx ny nz' or 'endsolid'");
    if (iequals(tokens[0], "endsolid")) {
      // Several solids may follow each other in one file.
      if (!next()) break;
      if (!iequals(tokens[0], "solid")) expected("'solid name' or the end of the file");
      continue;
    }
    // The normal is recomputed from the vertices anyway, so its values are not checked.
    if (!iequals(tokens[0], "facet")) expected("'facet normal nx ny nz' or 'endsolid'");
    if (!next() || !is(2, "outer", "loop")) expected("'outer loop'");
    std::array<uint32_t, 3> triangle;
    for (int v = 0; v < 3; ++v) {
      double p[3];
      if (!next() || !is(4, "vertex") || !parse_double(tokens[1], p[0]) ||
          !parse_double(tokens[2], p[1]) || !parse_double(tokens[3], p[2])) {
        expected("'vertex x y z'");
      }
      // Rounded to float like binary STL coordinates, so both weld alike.
      float x = float(p[0]), y = float(p[1]), z = float(p[2]);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        fail(path, cat("line ", file.line(), ": vertex ", v, " of facet ", mesh.triangles.size(),
                       " has a coordinate that is not a finite float: '", excerpt(line), "'"));
      }
      triangle[v] = welder.add(x, y, z);
    }
    if (!next() || !is(1, "endloop")) expected("'endloop'");
    if (!next() || !is(1, "endfacet")) expected("'endfacet'");
    mesh.triangles.push_back(triangle);
    check_welded_memory(path, welder, mesh.triangles.size(), options);
  }
  mesh.positions_mm = welder.positions();
  return mesh;
}

// Tells binary from ASCII STL (by the size the header declares, then "solid") and reads it.
TriMesh read_stl(InputFile& file, const ReadOptions& options) {
  const std::string& path = file.path();
  unsigned char header[kStlHeaderBytes] = {};
  size_t got = file.read(header, sizeof header);
  if (got == kStlHeaderBytes) {
    uint64_t count = load_le32(header + 80);
    if (file.size() == kStlHeaderBytes + kStlRecordBytes * count) {
      return read_binary_stl(file, count, options);
    }
  }
  std::string_view start(reinterpret_cast<const char*>(header), got);
  size_t first = 0;
  while (first < start.size() && (is_space(start[first]) || start[first] == '\n')) ++first;
  bool solid = iequals(start.substr(first, 5), "solid");
  // Binary STL headers often begin with "solid" too; a NUL byte (padding, or the high bytes of
  // the triangle count) shows that this one is binary.
  bool text = start.find('\0') == std::string_view::npos;
  if (solid && text) {
    file.rewind();
    return read_ascii_stl(file, options);
  }
  if (got < kStlHeaderBytes) {
    fail(path, cat("the file has ", got, " bytes: too short for a binary STL (at least ",
                   kStlHeaderBytes, ") and not an ASCII STL (which starts with 'solid')"));
  }
  uint64_t count = load_le32(header + 80);
  fail(path,
       cat("binary STL declares ", count, " triangles (", kStlHeaderBytes + kStlRecordBytes * count,
           " bytes) but the file has ", file.size(), " bytes"));
}

// Every statement of the OBJ specification that carries no triangle-mesh geometry.
bool is_ignored_obj_statement(std::string_view keyword) {
  static const char* const kIgnored[] = {
      "vt",        "vn",     "vp",     "g",     "o",        "s",        "mg",   "usemtl",
      "mtllib",    "usemap", "maplib", "l",     "p",        "cstype",   "deg",  "bmat",
      "step",      "curv",   "curv2",  "surf",  "parm",     "trim",     "hole", "scrv",
      "sp",        "end",    "con",    "bevel", "c_interp", "d_interp", "lod",  "shadow_obj",
      "trace_obj", "ctech",  "stech",  "call",  "csh"};
  for (const char* ignored : kIgnored) {
    if (keyword == ignored) return true;
  }
  return false;
}

// Reads v and f statements; faces are fanned, relative indices resolved as they come.
TriMesh read_obj(InputFile& file, const ReadOptions& options) {
  const std::string& path = file.path();
  TriMesh mesh;
  std::string line, continued;
  std::vector<std::string_view> tokens;
  std::vector<uint32_t> corners;
  uint64_t max_index = 0, max_index_line = 0;  // forward references are checked at the end
  auto bad = [&](const std::string& what) { fail(path, cat("line ", file.line(), ": ", what)); };
  while (file.read_line(line)) {
    while (!line.empty() && line.back() == '\\' && file.read_line(continued)) {
      line.back() = ' ';
      if (line.size() + continued.size() > kMaxLineBytes) bad("continued line is too long");
      line += continued;
    }
    if (file.line() == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0) line.erase(0, 3);
    size_t comment = line.find('#');
    split(std::string_view(line).substr(0, comment), tokens);
    if (tokens.empty()) continue;
    std::string_view keyword = tokens[0];
    if (keyword == "v") {
      double p[3];
      bool ok = tokens.size() >= 4 && tokens.size() <= 8;  // x y z, optional w or r g b [a]
      for (size_t i = 1; ok && i < tokens.size(); ++i) {
        double value;
        ok = parse_double(tokens[i], value);
        if (i <= 3) p[i - 1] = value;
      }
      if (!ok) bad(cat("expected 'v x y z [w]', got '", excerpt(line), "'"));
      Vec3d position{p[0], p[1], p[2]};
      if (!is_finite(position)) {
        bad(cat("vertex ", mesh.positions_mm.size() + 1, " has a non-finite coordinate"));
      }
      if (mesh.positions_mm.size() >= kMaxVertices) {
        throw ResourceLimit(cat(path, ": more than ", kMaxVertices, " vertices"));
      }
      mesh.positions_mm.push_back(position);
    } else if (keyword == "f" || keyword == "fo") {
      if (tokens.size() < 4) bad(cat("a face needs at least 3 vertices, got ", tokens.size() - 1));
      corners.clear();
      for (size_t i = 1; i < tokens.size(); ++i) {
        std::string_view corner = tokens[i];
        size_t slash = corner.find('/');
        int64_t index = 0, unused = 0;
        bool ok = parse_int(corner.substr(0, slash), index);
        if (ok && slash != std::string_view::npos) {
          std::string_view rest = corner.substr(slash + 1);  // "t", "t/n" or "/n"
          size_t second = rest.find('/');
          std::string_view texture = rest.substr(0, second);
          ok = texture.empty() ? second != std::string_view::npos : parse_int(texture, unused);
          if (ok && second != std::string_view::npos) {
            ok = parse_int(rest.substr(second + 1), unused);
          }
        }
        if (!ok) {
          bad(cat("expected a face vertex 'i', 'i/t', 'i//n' or 'i/t/n', got '", excerpt(corner),
                  "'"));
        }
        if (index == 0) bad("vertex index 0 (OBJ indices start at 1)");
        uint64_t resolved;
        if (index < 0) {
          if (uint64_t(-(index + 1)) >= mesh.positions_mm.size()) {
            bad(cat("relative vertex index ", index, " reaches before the first vertex (",
                    mesh.positions_mm.size(), " defined so far)"));
          }
          resolved = mesh.positions_mm.size() - uint64_t(-(index + 1)) - 1;
        } else {
          resolved = uint64_t(index) - 1;
          if (resolved >= kMaxVertices) bad(cat("vertex index ", index, " is too large"));
          if (resolved >= max_index) {
            if (resolved > max_index || max_index_line == 0) max_index_line = file.line();
            max_index = resolved;
          }
        }
        corners.push_back(static_cast<uint32_t>(resolved));
      }
      for (size_t i = 1; i + 1 < corners.size(); ++i) {
        mesh.triangles.push_back({corners[0], corners[i], corners[i + 1]});
      }
    } else if (!is_ignored_obj_statement(keyword)) {
      bad(cat("unknown statement '", excerpt(keyword), "'"));
    }
    check_memory(path,
                 double(mesh.positions_mm.size()) * kVertexBytes +
                     double(mesh.triangles.size()) * kTriangleBytes,
                 options, [&] {
                   return cat(mesh.positions_mm.size(), " vertices and ", mesh.triangles.size(),
                              " triangles");
                 });
  }
  if (max_index_line != 0 && max_index >= mesh.positions_mm.size()) {
    fail(path, cat("line ", max_index_line, ": vertex index ", max_index + 1, " is beyond the ",
                   mesh.positions_mm.size(), " vertices in the file"));
  }
  return mesh;
}

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };
enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

// The PLY type named `name` (both the classic and the sized spellings).
bool parse_ply_type(std::string_view name, PlyType& type) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUint8},
      {"uint8", PlyType::kUint8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUint16},  {"uint16", PlyType::kUint16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUint32},     {"uint32", PlyType::kUint32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [text, value] : kNames) {
    if (name == text) {
      type = value;
      return true;
    }
  }
  return false;
}

// Bytes per value in the binary encodings.
size_t ply_type_size(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

// Whether the type holds integers (list counts and indices must).
bool ply_is_integer(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }

// One property of a PLY element: a scalar or a list.
struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // the item type of a list
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

// One element of a PLY header, with its declared record count.
struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
  uint64_t line = 0;  // the header line that declares it
};

// Reads the values of PLY records in either encoding, with the element, record and line or byte
// offset in every error message.
class PlyValues {
 public:
  PlyValues(InputFile& file, PlyFormat format) : file_(file), format_(format) {}

  // Starts record `index` of `element`; in ASCII, reads its line.
  void begin_record(const PlyElement& element, uint64_t index) {
    element_ = &element;
    index_ = index;
    record_offset_ = file_.offset();
    if (format_ != PlyFormat::kAscii) return;
    do {
      if (!file_.read_line(line_)) {
        fail(file_.path(), cat("the file ends at ", element.name, " ", index, " of ", element.count,
                               " (after line ", file_.line(), ")"));
      }
      split(line_, tokens_);
    } while (tokens_.empty());
    next_token_ = 0;
  }

  // The next value of the record, converted to double (exact for every PLY type).
  double next(PlyType type) {
    if (format_ == PlyFormat::kAscii) {
      if (next_token_ == tokens_.size()) error("fewer values than its properties need");
      std::string_view token = tokens_[next_token_++];
      double value;
      if (!parse_double(token, value)) error(cat("expected a number, got '", excerpt(token), "'"));
      if (ply_is_integer(type) && value != std::floor(value)) {
        error(cat("expected an integer, got '", excerpt(token), "'"));
      }
      return value;
    }
    unsigned char bytes[8];
    size_t size = ply_type_size(type);
    if (file_.read(bytes, size) != size) truncated();
    uint64_t bits = 0;
    for (size_t i = 0; i < size; ++i) {
      size_t shift = format_ == PlyFormat::kBinaryLittleEndian ? i : size - 1 - i;
      bits |= uint64_t{bytes[i]} << (8 * shift);
    }
    switch (type) {
      case PlyType::kInt8:
        return int8_t(uint8_t(bits));
      case PlyType::kUint8:
        return uint8_t(bits);
      case PlyType::kInt16:
        return int16_t(uint16_t(bits));
      case PlyType::kUint16:
        return uint16_t(bits);
      case PlyType::kInt32:
        return int32_t(uint32_t(bits));
      case PlyType::kUint32:
        return uint32_t(bits);
      case PlyType::kFloat32: {
        uint32_t narrow = uint32_t(bits);
        float value;
        std::memcpy(&value, &narrow, sizeof value);
        return value;
      }
      case PlyType::kFloat64: {
        double value;
        std::memcpy(&value, &bits, sizeof value);
        return value;
      }
    }
    return 0;
  }

  // Throws unless `count` more values of this type follow (bounds a list before reading it).
  void require(double count, PlyType type) const {
    if (format_ == PlyFormat::kAscii) {
      size_t left = tokens_.size() - next_token_;
      if (count > double(left)) {
        error(cat("a list of ", count, " values, but only ", left, " follow"));
      }
    } else if (count * double(ply_type_size(type)) > double(file_.size() - file_.offset())) {
      truncated();
    }
  }

  // In ASCII, checks that the line held no more values than the properties.
  void end_record() {
    if (format_ == PlyFormat::kAscii && next_token_ != tokens_.size()) {
      error("more values than its properties");
    }
  }

  // Throws: the binary data ends inside the current record.
  [[noreturn]] void truncated() const {
    fail(file_.path(), cat("binary data ends inside ", element_->name, " ", index_, " of ",
                           element_->count, " (byte offset ", record_offset_, ")"));
  }

  // Throws InvalidInput locating the current record.
  [[noreturn]] void error(const std::string& what) const {
    std::string where = format_ == PlyFormat::kAscii ? cat("line ", file_.line())
                                                     : cat("byte offset ", record_offset_);
    fail(file_.path(), cat(where, ": ", element_->name, " ", index_, ": ", what));
  }

 private:
  InputFile& file_;
  PlyFormat format_;
  const PlyElement* element_ = nullptr;
  uint64_t index_ = 0;
  uint64_t record_offset_ = 0;
  std::string line_;
  std::vector<std::string_view> tokens_;
  size_t next_token_ = 0;
};

// Parses the header, bounds the declared counts, then reads every element in order.
TriMesh read_ply(InputFile& file, const ReadOptions& options) {
  const std::string& path = file.path();
  std::string line;
  std::vector<std::string_view> tokens;
  auto bad = [&](const std::string& what) { fail(path, cat("line ", file.line(), ": ", what)); };
  if (!file.read_line(line) || line != "ply") {
    fail(path, cat("line 1: expected 'ply', got '", excerpt(line), "'"));
  }
  bool has_format = false;
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  for (;;) {
    if (!file.read_line(line)) {
      fail(path, cat("expected 'end_header' but the file ends after line ", file.line()));
    }
    split(line, tokens);
    if (tokens.empty() || tokens[0] == "comment" || tokens[0] == "obj_info") continue;
    if (tokens[0] == "end_header" && tokens.size() == 1) break;
    if (tokens[0] == "format") {
      if (tokens.size() != 3 || tokens[2] != "1.0") {
        bad(cat("expected 'format <encoding> 1.0', got '", excerpt(line), "'"));
      }
      if (tokens[1] == "ascii") {
        format = PlyFormat::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        format = PlyFormat::kBinaryLittleEndian;
      } else if (tokens[1] == "binary_big_endian") {
        format = PlyFormat::kBinaryBigEndian;
      } else {
        bad(cat("unknown format '", excerpt(tokens[1]),
                "' (expected ascii, binary_little_endian or binary_big_endian)"));
      }
      has_format = true;
    } else if (tokens[0] == "element") {
      PlyElement element;
      if (tokens.size() != 3 || !parse_uint(tokens[2], element.count)) {
        bad(cat("expected 'element <name> <count>', got '", excerpt(line), "'"));
      }
      element.name = std::string(tokens[1]);
      element.line = file.line();
      elements.push_back(std::move(element));
    } else if (tokens[0] == "property") {
      if (elements.empty()) bad("property before the first element");
      PlyProperty property;
      bool ok;
      if (tokens.size() == 5 && tokens[1] == "list") {
        property.is_list = true;
        ok = parse_ply_type(tokens[2], property.count_type) &&
             ply_is_integer(property.count_type) && parse_ply_type(tokens[3], property.type);
        property.name = std::string(tokens[4]);
      } else {
        ok = tokens.size() == 3 && parse_ply_type(tokens[1], property.type);
        // (tokens beyond size() are views into an earlier line, freed since.)
        if (ok) property.name = std::string(tokens[2]);
      }
      if (!ok) {
        bad(
            cat("expected 'property <type> <name>' or 'property list <integer type> <type> "
                "<name>', got '",
                excerpt(line), "'"));
      }
      elements.back().properties.push_back(std::move(property));
    } else {
      bad(cat("unexpected header line '", excerpt(line), "'"));
    }
  }
  if (!has_format) fail(path, "the header has no 'format' line");

  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  for (const PlyElement& element : elements) {
    if (element.name == "vertex" && !vertex) vertex = &element;
    if (element.name == "face" && !face) face = &element;
  }
  if (!vertex) fail(path, "the header declares no 'vertex' element");
  if (!face) fail(path, "the header declares no 'face' element");
  int xyz[3] = {-1, -1, -1};
  for (size_t i = 0; i < vertex->properties.size(); ++i) {
    const PlyProperty& property = vertex->properties[i];
    for (int axis = 0; axis < 3; ++axis) {
      if (property.name == std::string(1, char('x' + axis)) && !property.is_list && xyz[axis] < 0) {
        xyz[axis] = int(i);
      }
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (xyz[axis] < 0) {
      fail(path, cat("line ", vertex->line, ": the vertex element has no '", char('x' + axis),
                     "' property"));
    }
  }
  int indices = -1;
  for (size_t i = 0; i < face->properties.size(); ++i) {
    const PlyProperty& property = face->properties[i];
    if ((property.name == "vertex_indices" || property.name == "vertex_index") && indices < 0) {
      if (!property.is_list || !ply_is_integer(property.type)) {
        fail(path, cat("line ", face->line, ": '", property.name, "' must be a list of integers"));
      }
      indices = int(i);
    }
  }
  if (indices < 0) {
    fail(path, cat("line ", face->line, ": the face element has no 'vertex_indices' list"));
  }

  // Declared counts must fit in the rest of the file before anything is allocated for them.
  uint64_t remaining = file.size() - file.offset();
  for (const PlyElement& element : elements) {
    if (element.properties.empty()) continue;
    uint64_t record_bytes = 2;  // an ASCII record is at least one digit and a line break
    if (format != PlyFormat::kAscii) {
      record_bytes = 0;
      for (const PlyProperty& property : element.properties) {
        record_bytes += ply_type_size(property.is_list ? property.count_type : property.type);
      }
    }
    if (element.count > remaining / record_bytes) {
      fail(path, cat("line ", element.line, ": declares ", element.count, " ", element.name,
                     " records of at least ", record_bytes, " bytes, but only ", remaining,
                     " bytes remain in the file"));
    }
    remaining -= element.count * record_bytes;
  }
  if (vertex->count > kMaxVertices) {
    throw ResourceLimit(
        cat(path, ": ", vertex->count, " vertices are more than 32-bit indices address"));
  }
  check_memory(path, double(vertex->count) * kVertexBytes + double(face->count) * kTriangleBytes,
               options,
               [&] { return cat(vertex->count, " vertices and ", face->count, " faces"); });

  TriMesh mesh;
  mesh.positions_mm.reserve(vertex->count);
  mesh.triangles.reserve(face->count);
  PlyValues values(file, format);
  std::vector<uint32_t> corners;
  for (const PlyElement& element : elements) {
    if (element.properties.empty()) continue;
    for (uint64_t index = 0; index < element.count; ++index) {
      values.begin_record(element, index);
      Vec3d position;
      for (size_t i = 0; i < element.properties.size(); ++i) {
        const PlyProperty& property = element.properties[i];
        if (!property.is_list) {
          double value = values.next(property.type);
          for (int axis = 0; axis < 3; ++axis) {
            if (&element == vertex && int(i) == xyz[axis]) position[axis] = value;
          }
          continue;
        }
        double count = values.next(property.count_type);
        bool is_face = &element == face && int(i) == indices;
        if (count < 0) values.error(cat("negative list length ", count));
        if (is_face && count < 3) {
          values.error(cat("a face needs at least 3 vertices, got ", count));
        }
        values.require(count, property.type);
        corners.clear();
        for (uint64_t k = 0; k < uint64_t(count); ++k) {
          double value = values.next(property.type);
          if (!is_face) continue;
          if (value < 0 || value >= double(vertex->count)) {
            values.error(
                cat("vertex index ", value, " is out of range (", vertex->count, " vertices)"));
          }
          corners.push_back(static_cast<uint32_t>(value));
        }
        for (size_t k = 1; k + 1 < corners.size(); ++k) {
          mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
        }
      }
      values.end_record();
      if (&element == vertex) {
        if (!is_finite(position)) values.error("non-finite coordinate");
        mesh.positions_mm.push_back(position);
      }
      if (&element == face) {
        check_memory(
            path,
            double(vertex->count) * kVertexBytes + double(mesh.triangles.size()) * kTriangleBytes,
            options, [&] {
              return cat(vertex->count, " vertices and ", mesh.triangles.size(), " triangles");
            });
      }
    }
  }
  // More records than the header declares mean a header that does not describe the file.
  const std::string declared = cat("the header declares ", vertex->count, " vertices and ", face->count, " faces");
  if (format == PlyFormat::kAscii) {
    while (file.read_line(line)) {
      split(line, tokens);
      if (!tokens.empty()) bad(cat("more data than ", declared, ": '", excerpt(line), "'"));
    }
  } else if (file.offset() != file.size()) {
    fail(path, cat(file.size() - file.offset(), " bytes after the records ", declared, " (at byte ", file.offset(), ")"));
  }
  return mesh;
}

// Removes what a failed write left at `path`, unless that is no regular file (say /dev/full).
void remove_partial(const std::string& path) {
  struct stat info;
  if (::stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode)) std::remove(path.c_str());
}

// Whether an STL header begins with "solid" (after whitespace, any case).
bool starts_with_solid(const std::string& header) {
  size_t first = header.find_first_not_of(" \t\r\n\v\f");
  return first != std::string::npos && iequals(std::string_view(header).substr(first, 5), "solid");
}

}  // namespace

MeshFormat mesh_format_from_path(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".stl") return MeshFormat::kStl;
  if (extension == ".obj") return MeshFormat::kObj;
  if (extension == ".ply") return MeshFormat::kPly;
  if (extension == ".3mf") return MeshFormat::k3mf;
  if (extension == ".drc") return MeshFormat::kDrc;
  fail(path,
       extension.empty()
           ? "the file name has no extension (expected .stl, .obj, .ply, .3mf or .drc)"
           : cat("unknown mesh format '", extension, "' (expected .stl, .obj, .ply, .3mf or .drc)"));
}

const char* mesh_format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::kStl:
      return "STL";
    case MeshFormat::kObj:
      return "OBJ";
    case MeshFormat::kPly:
      return "PLY";
    case MeshFormat::k3mf:
      return "3MF";
    case MeshFormat::kDrc:
      return "Draco";
  }
  return "unknown";
}

TriMesh read_mesh(const std::string& path, const ReadOptions& options) {
  return read_mesh(path, mesh_format_from_path(path), options);
}

TriMesh read_mesh(const std::string& path, MeshFormat format, const ReadOptions& options) {
  if (regular_file_size(path) == 0) fail(path, "the file is empty");
  TriMesh mesh;
  if (format == MeshFormat::k3mf) {
    mesh = read_3mf(path, options);
  } else if (format == MeshFormat::kDrc) {
    mesh = read_draco(path, options);
  } else {
    InputFile file(path);
    if (format == MeshFormat::kStl) mesh = read_stl(file, options);
    if (format == MeshFormat::kObj) mesh = read_obj(file, options);
    if (format == MeshFormat::kPly) mesh = read_ply(file, options);
  }
  if (mesh.triangles.empty()) fail(path, "the file has no triangles");
  return mesh;
}

struct StlWriter::Impl {
  std::string path;
  std::FILE* file = nullptr;
  std::vector<unsigned char> buffer;
  uint64_t triangles = 0;
  bool finished = false;

  [[noreturn]] void fail() {
    const int error = errno;
    if (file) std::fclose(file);
    file = nullptr;
    remove_partial(path);
    throw IoError(cat("cannot write '", path, "': ", std::strerror(error)));
  }
  void flush() {
    if (!buffer.empty() && std::fwrite(buffer.data(), 1, buffer.size(), file) != buffer.size()) fail();
    buffer.clear();
  }
};

StlWriter::StlWriter(const std::string& path, const std::string& header) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.file = std::fopen(path.c_str(), "wb");
  if (!m.file) throw IoError(cat("cannot create '", path, "': ", std::strerror(errno)));
  m.buffer.reserve(kIoChunkBytes);
  // Other programs take a binary STL whose header begins with "solid" for an ASCII one.
  std::string text = starts_with_solid(header) ? "binary " + header : header;
  text.resize(80, ' ');
  m.buffer.insert(m.buffer.end(), text.begin(), text.end());
  m.buffer.resize(kStlHeaderBytes);  // the count: written by finish()
}

StlWriter::~StlWriter() {
  if (impl_->finished) return;
  if (impl_->file) std::fclose(impl_->file);
  remove_partial(impl_->path);
}

void StlWriter::add(const std::array<Vec3d, 3>& corners) {
  Impl& m = *impl_;
  if (m.triangles == std::numeric_limits<uint32_t>::max()) {
    throw ResourceLimit(cat("cannot write '", m.path, "': more than ", m.triangles,
                            " triangles are more than a binary STL holds"));
  }
  float p[3][3];
  Vec3d corner[3];
  for (int v = 0; v < 3; ++v) {
    for (int axis = 0; axis < 3; ++axis) p[v][axis] = static_cast<float>(corners[size_t(v)][axis]);
    corner[v] = {p[v][0], p[v][1], p[v][2]};
  }
  // The normal of the triangle as stored (float), so that it matches what readers see.
  Vec3d normal = cross(corner[1] - corner[0], corner[2] - corner[0]);
  double length = norm(normal);
  normal = length > 0 && std::isfinite(length) ? normal / length : Vec3d{};
  size_t at = m.buffer.size();
  m.buffer.resize(at + kStlRecordBytes);
  unsigned char* record = m.buffer.data() + at;
  for (int axis = 0; axis < 3; ++axis) store_le_float(static_cast<float>(normal[axis]), record + 4 * axis);
  for (int v = 0; v < 3; ++v)
    for (int axis = 0; axis < 3; ++axis) store_le_float(p[v][axis], record + 12 + 12 * v + 4 * axis);
  record[48] = record[49] = 0;
  ++m.triangles;
  if (m.buffer.size() + kStlRecordBytes > kIoChunkBytes) m.flush();
}

uint64_t StlWriter::triangles() const { return impl_->triangles; }

void StlWriter::finish() {
  Impl& m = *impl_;
  if (m.finished) return;
  m.flush();
  unsigned char count[4];
  store_le32(static_cast<uint32_t>(m.triangles), count);
  if (std::fseek(m.file, 80, SEEK_SET) != 0 || std::fwrite(count, 1, 4, m.file) != 4) m.fail();
  const int closed = std::fclose(m.file);
  m.file = nullptr;
  if (closed != 0) m.fail();
  m.finished = true;
}

void write_stl(const std::string& path, const TriMesh& mesh, const std::string& header) {
  if (mesh.triangles.size() > std::numeric_limits<uint32_t>::max()) {
    throw ResourceLimit(cat("cannot write '", path, "': ", mesh.triangles.size(),
                            " triangles are more than a binary STL holds"));
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (uint32_t v : mesh.triangles[t]) {
      if (v >= mesh.positions_mm.size()) {
        throw InvalidInput(cat("cannot write '", path, "': triangle ", t, " refers to vertex ", v,
                               " of ", mesh.positions_mm.size()));
      }
    }
  }
  StlWriter writer(path, header);
  for (const auto& t : mesh.triangles)
    writer.add({mesh.positions_mm[t[0]], mesh.positions_mm[t[1]], mesh.positions_mm[t[2]]});
  writer.finish();
}

std::vector<std::array<Vec3d, 3>> read_stl_triangles(const std::string& path, uint64_t first, uint64_t count) {
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw IoError(cat("cannot open '", path, "': ", std::strerror(errno)));
  unsigned char head[kStlHeaderBytes];
  if (std::fread(head, 1, kStlHeaderBytes, file.get()) != kStlHeaderBytes)
    throw InvalidInput(cat(path, ": not a binary STL (shorter than its 84-byte header)"));
  const uint64_t total = uint64_t(head[80]) | uint64_t(head[81]) << 8 | uint64_t(head[82]) << 16 | uint64_t(head[83]) << 24;
  if (first > total || count > total - first)
    throw InvalidInput(cat(path, ": triangles ", first, " to ", first + count, " asked of ", total));
  if (std::fseek(file.get(), long(kStlHeaderBytes + first * kStlRecordBytes), SEEK_SET) != 0)
    throw IoError(cat("cannot read '", path, "': ", std::strerror(errno)));
  std::vector<std::array<Vec3d, 3>> out(count);
  std::vector<unsigned char> buffer(kIoChunkBytes / kStlRecordBytes * kStlRecordBytes);
  for (uint64_t done = 0; done < count;) {
    const uint64_t n = std::min<uint64_t>(count - done, buffer.size() / kStlRecordBytes);
    if (std::fread(buffer.data(), 1, n * kStlRecordBytes, file.get()) != n * kStlRecordBytes)
      throw InvalidInput(cat(path, ": ends before triangle ", first + done + n, " of ", total));
    for (uint64_t i = 0; i < n; ++i)
      for (int v = 0; v < 3; ++v)
        for (int axis = 0; axis < 3; ++axis) {
          float f;
          const unsigned char* q = buffer.data() + i * kStlRecordBytes + 12 + 12 * v + 4 * axis;
          const uint32_t bits = uint32_t(q[0]) | uint32_t(q[1]) << 8 | uint32_t(q[2]) << 16 | uint32_t(q[3]) << 24;
          std::memcpy(&f, &bits, 4);
          out[done + i][size_t(v)][axis] = f;
        }
    done += n;
  }
  return out;
}

}  // namespace lacuna
