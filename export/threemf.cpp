// 3MF reading through lib3mf 1.8's C interface; writing with libzip (exact float32 coordinates).
#include <sys/stat.h>

#include <zip.h>

#include <cctype>
#include <charconv>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <new>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "Model/COM/NMR_DLLInterfaces.h"
#include "errors.h"
#include "export/mesh_io.h"
#include "export/zip_archive.h"

namespace lacuna {
namespace {

using NMR::PLib3MFBase;

constexpr int kMaxComponentDepth = 32;
constexpr float kMaxCoordinateMm =
    1e9f;  // lib3mf refuses coordinates beyond (NMR_MESH_MAXCOORDINATE)
constexpr uint64_t kMaxIndex = 0xffffffffu;

// Concatenates the arguments as an ostream would print them.
template <typename... Args>
std::string cat(const Args&... args) {
  std::ostringstream out;
  (out << ... << args);
  return out.str();
}

// Owns one lib3mf object and releases it.
class Handle {
 public:
  Handle() = default;
  ~Handle() { reset(); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  PLib3MFBase* get() const { return handle_; }
  // For lib3mf's output parameters; releases what the handle held.
  PLib3MFBase** out() {
    reset();
    return &handle_;
  }

 private:
  void reset() {
    if (handle_) NMR::lib3mf_release(handle_);
    handle_ = nullptr;
  }

  PLib3MFBase* handle_ = nullptr;
};

// lib3mf's message for the last failure of `instance`.
std::string last_error(PLib3MFBase* instance) {
  DWORD code = 0;
  const char* message = nullptr;
  if (instance && NMR::lib3mf_getlasterror(instance, &code, &message) == LIB3MF_OK && message &&
      *message) {
    return cat(message, " (lib3mf error ", code, ")");
  }
  return "unknown lib3mf error";
}

// Throws Error with lib3mf's message if `result` reports a failure of `instance`'s method.
template <typename Error>
void check(int result, PLib3MFBase* instance, const std::string& context) {
  if (result != LIB3MF_OK) throw Error(context + ": " + last_error(instance));
}

// An affine map p -> m[:, 0:3] p + m[:, 3] (lib3mf's MODELTRANSFORM layout).
struct Affine {
  double m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  Vec3d operator()(const Vec3d& p) const {
    Vec3d q;
    for (int r = 0; r < 3; ++r) q[r] = m[r][0] * p.x + m[r][1] * p.y + m[r][2] * p.z + m[r][3];
    return q;
  }
  double determinant() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
};

Affine from_lib3mf(const NMR::MODELTRANSFORM& t) {
  Affine a;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) a.m[r][c] = t.m_fFields[r][c];
  }
  return a;
}

// outer(inner(p)).
Affine compose(const Affine& outer, const Affine& inner) {
  Affine a;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      a.m[r][c] = outer.m[r][0] * inner.m[0][c] + outer.m[r][1] * inner.m[1][c] +
                  outer.m[r][2] * inner.m[2][c] + (c == 3 ? outer.m[r][3] : 0);
    }
  }
  return a;
}

// The length of a 3MF model unit in millimetres.
double millimetres_per_unit(DWORD unit) {
  switch (unit) {
    case NMR::MODELUNIT_MICROMETER:
      return 0.001;
    case NMR::MODELUNIT_CENTIMETER:
      return 10;
    case NMR::MODELUNIT_INCH:
      return 25.4;
    case NMR::MODELUNIT_FOOT:
      return 304.8;
    case NMR::MODELUNIT_METER:
      return 1000;
    default:
      return 1;
  }
}

// The total uncompressed size of a zip archive's entries from its central directory, or -1 if
// the directory cannot be read (lib3mf then reports what is wrong).
double zip_uncompressed_bytes(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), std::fclose);
  struct stat info;
  if (!file || ::fstat(fileno(file.get()), &info) != 0) return -1;
  uint64_t size = uint64_t(info.st_size);
  std::vector<unsigned char> data;
  auto read_at = [&](uint64_t offset, uint64_t bytes) {
    if (offset > size || bytes > size - offset) return false;
    data.resize(bytes);
    return std::fseek(file.get(), long(offset), SEEK_SET) == 0 &&
           std::fread(data.data(), 1, bytes, file.get()) == bytes;
  };
  auto u16 = [&](size_t at) { return uint32_t{data[at]} | uint32_t{data[at + 1]} << 8; };
  auto u32 = [&](size_t at) { return u16(at) | u16(at + 2) << 16; };
  auto u64 = [&](size_t at) { return uint64_t{u32(at)} | uint64_t{u32(at + 4)} << 32; };

  // The end record is within the last 22 + 65535 bytes (its comment can be that long).
  uint64_t tail = std::min<uint64_t>(size, 22 + 0xffff);
  if (tail < 22 || !read_at(size - tail, tail)) return -1;
  size_t end = tail - 22 + 1;
  while (end-- > 0 && u32(end) != 0x06054b50) {
  }
  if (end > tail) return -1;
  uint64_t directory_bytes = u32(end + 12), directory_offset = u32(end + 16);
  if (directory_offset == 0xffffffff || directory_bytes == 0xffffffff) {
    // Zip64 (lib3mf writes it): a locator just before the end record points at the zip64 end
    // record, which holds the real values.
    if (end < 20 || u32(end - 20) != 0x07064b50) return -1;
    if (!read_at(u64(end - 20 + 8), 56) || u32(0) != 0x06064b50) return -1;
    directory_bytes = u64(40);
    directory_offset = u64(48);
  }
  if (!read_at(directory_offset, directory_bytes)) return -1;
  double total = 0;
  for (size_t entry = 0; entry + 46 <= data.size() && u32(entry) == 0x02014b50;) {
    uint64_t unpacked = u32(entry + 24);
    size_t extra = entry + 46 + u16(entry + 28),
           extra_end = std::min(data.size(), extra + u16(entry + 30));
    // A size of 0xffffffff means the 64-bit size is in the zip64 extra field (id 1), first.
    for (size_t field = extra; unpacked == 0xffffffff && field + 4 <= extra_end;
         field += 4 + u16(field + 2)) {
      if (u16(field) == 1 && u16(field + 2) >= 8 && field + 12 <= extra_end) {
        unpacked = u64(field + 4);
      }
    }
    total += double(unpacked);
    entry = extra_end + u16(entry + 32);
  }
  return total;
}

// Collects the triangles of a model's build items, in millimetres.
class ModelReader {
 public:
  ModelReader(const std::string& path, double scale) : path_(path), scale_(scale) {}

  // Vertices and triangles that appending `object` would add (memoized per resource).
  std::pair<double, double> count(PLib3MFBase* object, int depth) {
    DWORD id = resource_id(object);
    if (auto found = counts_.find(id); found != counts_.end()) return found->second;
    check_depth(depth);
    std::pair<double, double> total{0, 0};
    if (is_mesh(object)) {
      DWORD vertices = 0, triangles = 0;
      check<InvalidInput>(NMR::lib3mf_meshobject_getvertexcount(object, &vertices), object,
                          context(id));
      check<InvalidInput>(NMR::lib3mf_meshobject_gettrianglecount(object, &triangles), object,
                          context(id));
      total = {vertices, triangles};
    } else {
      for_each_component(object, id, [&](PLib3MFBase* child, const Affine&) {
        auto [v, t] = count(child, depth + 1);
        total.first += v;
        total.second += t;
      });
    }
    counts_[id] = total;
    return total;
  }

  // Appends `object`'s triangles, placed by `transform`.
  void append(PLib3MFBase* object, const Affine& transform, TriMesh& mesh, int depth) {
    DWORD id = resource_id(object);
    check_depth(depth);
    if (!is_mesh(object)) {
      for_each_component(object, id, [&](PLib3MFBase* child, const Affine& placement) {
        append(child, compose(transform, placement), mesh, depth + 1);
      });
      return;
    }
    DWORD vertex_count = 0, triangle_count = 0;
    check<InvalidInput>(NMR::lib3mf_meshobject_getvertexcount(object, &vertex_count), object,
                        context(id));
    check<InvalidInput>(NMR::lib3mf_meshobject_gettrianglecount(object, &triangle_count), object,
                        context(id));
    std::vector<NMR::MODELMESHVERTEX> vertices(vertex_count);
    std::vector<NMR::MODELMESHTRIANGLE> triangles(triangle_count);
    DWORD got = 0;
    if (vertex_count > 0) {
      check<InvalidInput>(
          NMR::lib3mf_meshobject_getvertices(object, vertices.data(), vertex_count, &got), object,
          context(id));
    }
    if (triangle_count > 0) {
      check<InvalidInput>(
          NMR::lib3mf_meshobject_gettriangleindices(object, triangles.data(), triangle_count, &got),
          object, context(id));
    }
    uint64_t base = mesh.positions_mm.size();
    if (base + vertex_count > kMaxIndex) {
      throw ResourceLimit(cat(path_, ": more than ", kMaxIndex, " vertices"));
    }
    for (DWORD i = 0; i < vertex_count; ++i) {
      const float* p = vertices[i].m_fPosition;
      Vec3d position = transform(Vec3d{p[0], p[1], p[2]}) * scale_;
      if (!is_finite(position)) {
        throw InvalidInput(cat(context(id), ": vertex ", i, " has a non-finite coordinate"));
      }
      mesh.positions_mm.push_back(position);
    }
    // A mirroring placement turns the surface inside out; reversing the triangles restores it.
    bool mirrored = transform.determinant() < 0;
    for (DWORD i = 0; i < triangle_count; ++i) {
      const DWORD* v = triangles[i].m_nIndices;
      for (int k = 0; k < 3; ++k) {
        if (v[k] >= vertex_count) {
          throw InvalidInput(
              cat(context(id), ": triangle ", i, " refers to vertex ", v[k], " of ", vertex_count));
        }
      }
      uint32_t a = uint32_t(base + v[0]), b = uint32_t(base + v[1]), c = uint32_t(base + v[2]);
      mesh.triangles.push_back(mirrored ? std::array<uint32_t, 3>{a, c, b}
                                        : std::array<uint32_t, 3>{a, b, c});
    }
  }

 private:
  // "<path>: object <id>", the prefix of messages about one object.
  std::string context(DWORD id) const { return cat(path_, ": object ", id); }

  // Throws InvalidInput beyond kMaxComponentDepth (a guard against cyclic references).
  void check_depth(int depth) const {
    if (depth > kMaxComponentDepth) {
      throw InvalidInput(
          cat(path_, ": components nest more than ", kMaxComponentDepth, " levels deep"));
    }
  }

  DWORD resource_id(PLib3MFBase* object) const {
    DWORD id = 0;
    check<InvalidInput>(NMR::lib3mf_resource_getresourceid(object, &id), object, path_);
    return id;
  }

  bool is_mesh(PLib3MFBase* object) const {
    BOOL mesh = false;
    check<InvalidInput>(NMR::lib3mf_object_ismeshobject(object, &mesh), object, path_);
    return mesh;
  }

  // Calls visit(child object, placement) for each component of a components object.
  template <typename Visit>
  void for_each_component(PLib3MFBase* object, DWORD id, Visit visit) {
    BOOL components = false;
    check<InvalidInput>(NMR::lib3mf_object_iscomponentsobject(object, &components), object,
                        context(id));
    if (!components) return;  // neither mesh nor components: nothing to build
    DWORD n = 0;
    check<InvalidInput>(NMR::lib3mf_componentsobject_getcomponentcount(object, &n), object,
                        context(id));
    for (DWORD i = 0; i < n; ++i) {
      Handle component, child;
      check<InvalidInput>(NMR::lib3mf_componentsobject_getcomponent(object, i, component.out()),
                          object, context(id));
      check<InvalidInput>(NMR::lib3mf_component_getobjectresource(component.get(), child.out()),
                          component.get(), context(id));
      BOOL has_transform = false;
      NMR::MODELTRANSFORM t;
      Affine placement;
      check<InvalidInput>(NMR::lib3mf_component_hastransform(component.get(), &has_transform),
                          component.get(), context(id));
      if (has_transform) {
        check<InvalidInput>(NMR::lib3mf_component_gettransform(component.get(), &t),
                            component.get(), context(id));
        placement = from_lib3mf(t);
      }
      visit(child.get(), placement);
    }
  }

  const std::string& path_;
  double scale_;  // millimetres per model unit
  std::map<DWORD, std::pair<double, double>> counts_;
};

// FNV-1a, continued from `hash`, over raw bytes.
uint64_t fnv1a(uint64_t hash, const void* data, size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 0x100000001b3ull;
  return hash;
}

// FNV-1a over a length-prefixed string (so that concatenations do not collide).
uint64_t fnv1a(uint64_t hash, const std::string& text) {
  uint64_t size = text.size();
  return fnv1a(fnv1a(hash, &size, sizeof size), text.data(), text.size());
}

// The splitmix64 finalizer: spreads every input bit over the output.
uint64_t mix(uint64_t x) {
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// A UUID (RFC 9562 version 8, "custom") derived from a content hash and the element it names.
std::string content_uuid(uint64_t hash, uint64_t role) {
  uint64_t high = mix(hash + role * 0x9e3779b97f4a7c15ull);
  uint64_t low = mix(high ^ 0x5851f42d4c957f2dull);
  high = (high & ~uint64_t{0xf000}) | 0x8000;
  low = (low & ~(uint64_t{3} << 62)) | uint64_t{2} << 62;
  char text[40];
  std::snprintf(text, sizeof text, "%08x-%04x-%04x-%04x-%012llx", unsigned(high >> 32),
                unsigned(high >> 16 & 0xffff), unsigned(high & 0xffff), unsigned(low >> 48),
                static_cast<unsigned long long>(low & 0xffffffffffffull));
  return text;
}

// lib3mf 1.8 writes metadata values into the XML without escaping them.
std::string xml_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// Whether the text holds characters that XML 1.0 cannot represent.
bool has_control_character(const std::string& text) {
  for (unsigned char c : text) {
    if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') return true;
  }
  return false;
}


// lib3mf 1.8 walks every path through nested components while it reads, so a few kilobytes of
// components nested ten deep hang it. The model parts are scanned here first (streamed through
// libzip) and the build's number of object instances bounded before lib3mf sees the file.
constexpr double kMaxInstances = 1e6;
// lib3mf 1.8 reads a model part through 32-bit sizes: a larger part (a zip bomb) ends in unrelated
// errors ("No build section").
constexpr uint64_t kMaxModelPartBytes = (uint64_t{1} << 31) - 1;

// Whether `text` is a number as 3MF writes them (XML Schema ST_Number: [+-]digits[.digits][e[+-]digits]);
// lib3mf reads "abc" as 0 and "10abc" as 10.
bool is_xml_number(const std::string& text) {
  size_t i = 0, n = text.size();
  auto digits = [&] {
    const size_t start = i;
    while (i < n && text[i] >= '0' && text[i] <= '9') ++i;
    return i - start;
  };
  if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
  size_t mantissa = digits();
  if (i < n && text[i] == '.') {
    ++i;
    mantissa += digits();
  }
  if (mantissa == 0) return false;
  if (i < n && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
    if (digits() == 0) return false;
  }
  return i == n;
}

void precheck_components(const std::string& path) {
  int error = 0;
  std::unique_ptr<zip_t, int (*)(zip_t*)> archive(zip_open(path.c_str(), ZIP_RDONLY, &error), zip_close);
  if (!archive) return;  // not a zip: lib3mf says so in its own words
  std::map<std::string, std::vector<std::string>> children;  // object id -> component object ids
  std::vector<std::string> items;
  const zip_int64_t entries = zip_get_num_entries(archive.get(), 0);
  for (zip_int64_t e = 0; e < entries; ++e) {
    const char* name = zip_get_name(archive.get(), zip_uint64_t(e), 0);
    std::string entry = name ? name : "";
    if (entry.size() < 6 || entry.compare(entry.size() - 6, 6, ".model") != 0) continue;
    zip_stat_t stat;
    zip_stat_init(&stat);
    if (zip_stat_index(archive.get(), zip_uint64_t(e), 0, &stat) == 0 && (stat.valid & ZIP_STAT_SIZE) &&
        stat.size > kMaxModelPartBytes)
      throw ResourceLimit(cat(path, ": the model part ", entry, " unpacks to ", uint64_t(stat.size),
                              " bytes, more than the 2 GB a model part may have"));
    uint64_t unpacked = 0, vertex = 0;
    std::unique_ptr<zip_file_t, int (*)(zip_file_t*)> file(zip_fopen_index(archive.get(), zip_uint64_t(e), 0),
                                                           zip_fclose);
    if (!file) continue;
    std::string tag, current_object;
    bool in_tag = false;
    char buffer[1 << 16];
    // The value of attribute `key` (either quote, spaces around '=' allowed); empty when absent.
    auto attribute = [](const std::string& t, const char* key) {
      const std::string spaced = std::string(" ") + key;
      for (size_t at = t.find(spaced); at != std::string::npos; at = t.find(spaced, at + 1)) {
        size_t i = at + spaced.size();
        while (i < t.size() && t[i] == ' ') ++i;
        if (i >= t.size() || t[i] != '=') continue;
        ++i;
        while (i < t.size() && t[i] == ' ') ++i;
        if (i >= t.size() || (t[i] != '"' && t[i] != '\'')) continue;
        const size_t end = t.find(t[i], i + 1);
        return end == std::string::npos ? std::string() : t.substr(i + 1, end - i - 1);
      }
      return std::string();
    };
    for (zip_int64_t got; (got = zip_fread(file.get(), buffer, sizeof buffer)) > 0;) {
      // The directory's sizes can lie; what comes out is counted.
      unpacked += uint64_t(got);
      if (unpacked > kMaxModelPartBytes)
        throw ResourceLimit(cat(path, ": the model part ", entry, " unpacks to more than the 2 GB a model part may have"));
      for (zip_int64_t i = 0; i < got; ++i) {
        char c = buffer[i];
        if (!in_tag) {
          if (c == '<') {
            in_tag = true;
            tag.clear();
          }
          continue;
        }
        if (c != '>') {
          if (tag.size() < 4096) tag.push_back(c == '\t' || c == '\n' || c == '\r' ? ' ' : c);
          continue;
        }
        in_tag = false;
        if (tag.rfind("vertex ", 0) == 0) {
          for (const char* axis : {"x", "y", "z"}) {
            const std::string value = attribute(tag, axis);
            if (!is_xml_number(value))
              throw InvalidInput(cat(path, ": ", entry, ": vertex ", vertex, ": coordinate ", axis, "=\"",
                                     value.substr(0, 40), "\" is not a number"));
          }
          ++vertex;
        } else if (tag.rfind("!DOCTYPE", 0) == 0 || tag.rfind("!ENTITY", 0) == 0) {
          throw InvalidInput(cat(path, ": ", entry, ": holds a document type declaration (<!DOCTYPE>), which 3MF does not allow"));
        } else if (tag.rfind("object ", 0) == 0) {
          current_object = attribute(tag, "id");
          children[current_object];
        } else if (tag.rfind("/object", 0) == 0) {
          current_object.clear();
        } else if (tag.rfind("component ", 0) == 0 && !current_object.empty()) {
          children[current_object].push_back(attribute(tag, "objectid"));
        } else if (tag.rfind("item ", 0) == 0) {
          items.push_back(attribute(tag, "objectid"));
        }
      }
    }
  }
  // Instances per object, memoized; a cycle is an error of the file.
  std::map<std::string, double> instances;
  std::set<std::string> open;
  std::function<double(const std::string&, int)> count = [&](const std::string& id, int depth) -> double {
    if (auto found = instances.find(id); found != instances.end()) return found->second;
    if (depth > 64 || !open.insert(id).second)
      throw InvalidInput(cat(path, ": components of object ", id, " refer back to themselves or nest deeper than 64"));
    double n = 0;
    auto it = children.find(id);
    if (it == children.end() || it->second.empty()) n = 1;
    else
      for (const std::string& child : it->second) n += count(child, depth + 1);
    open.erase(id);
    return instances[id] = n;
  };
  double total = 0;
  for (const std::string& item : items) total += count(item, 0);
  if (total > kMaxInstances)
    throw ResourceLimit(cat(path, ": the build expands to ", total, " object instances through nested components,",
                            " more than ", uint64_t(kMaxInstances)));
}

}  // namespace

#if defined(__SANITIZE_ADDRESS__)  // GCC
#define LACUNA_ASAN 1
#elif defined(__has_feature)  // clang
#if __has_feature(address_sanitizer)
#define LACUNA_ASAN 1
#endif
#endif
#if defined(LACUNA_ASAN)
// lib3mf 1.8 never frees libzip's per-entry sources (about 160 bytes for each part read, 56 for
// each written); without this, every sanitizer run that touches a 3MF file fails on them.
extern "C" const char* __lsan_default_suppressions() { return "leak:libzip.so\n"; }
#endif

TriMesh read_3mf(const std::string& path, const ReadOptions& options) {
  precheck_components(path);
  // lib3mf unpacks the model before anything can be counted; the archive's directory bounds it.
  double unpacked = zip_uncompressed_bytes(path);
  if (unpacked > double(options.max_memory_bytes)) {
    throw ResourceLimit(cat(path, ": the 3MF package unpacks to ", uint64_t(unpacked),
                            " bytes (by its zip directory), more than the memory limit of ",
                            options.max_memory_bytes, " bytes"));
  }
  Handle model, reader;
  check<InvalidInput>(NMR::lib3mf_createmodel(model.out()), nullptr, path);
  check<InvalidInput>(NMR::lib3mf_model_queryreader(model.get(), "3mf", reader.out()), model.get(),
                      path);
  check<InvalidInput>(NMR::lib3mf_reader_readfromfileutf8(reader.get(), path.c_str()), reader.get(),
                      path + ": not a readable 3MF package");
  DWORD unit = NMR::MODELUNIT_MILLIMETER;
  check<InvalidInput>(NMR::lib3mf_model_getunit(model.get(), &unit), model.get(), path);
  ModelReader objects(path, millimetres_per_unit(unit));

  // Collect the items first so that the memory check sees the whole build.
  std::vector<std::pair<std::unique_ptr<Handle>, Affine>> items;
  double vertices = 0, triangles = 0;
  Handle iterator;
  check<InvalidInput>(NMR::lib3mf_model_getbuilditems(model.get(), iterator.out()), model.get(),
                      path);
  for (;;) {
    BOOL has_next = false;
    check<InvalidInput>(NMR::lib3mf_builditemiterator_movenext(iterator.get(), &has_next),
                        iterator.get(), path);
    if (!has_next) break;
    Handle item;
    auto object = std::make_unique<Handle>();
    check<InvalidInput>(NMR::lib3mf_builditemiterator_getcurrent(iterator.get(), item.out()),
                        iterator.get(), path);
    check<InvalidInput>(NMR::lib3mf_builditem_getobjectresource(item.get(), object->out()),
                        item.get(), path);
    BOOL has_transform = false;
    Affine placement;
    check<InvalidInput>(NMR::lib3mf_builditem_hasobjecttransform(item.get(), &has_transform),
                        item.get(), path);
    if (has_transform) {
      NMR::MODELTRANSFORM t;
      check<InvalidInput>(NMR::lib3mf_builditem_getobjecttransform(item.get(), &t), item.get(),
                          path);
      placement = from_lib3mf(t);
    }
    if (options.object_names) {
      ULONG needed = 0;
      check<InvalidInput>(NMR::lib3mf_object_getnameutf8(object->get(), nullptr, 0, &needed), object->get(), path);
      std::string name(size_t(needed) + 1, '\0');
      check<InvalidInput>(NMR::lib3mf_object_getnameutf8(object->get(), name.data(), ULONG(name.size()), &needed),
                          object->get(), path);
      name.resize(std::strlen(name.c_str()));
      options.object_names->push_back(name);
    }
    auto [v, t] = objects.count(object->get(), 0);
    vertices += v;
    triangles += t;
    items.emplace_back(std::move(object), placement);
  }
  // Positions and triangles, plus lib3mf's copy of the largest object while it is converted.
  double bytes = vertices * (sizeof(Vec3d) + sizeof(NMR::MODELMESHVERTEX)) +
                 triangles * 2 * sizeof(NMR::MODELMESHTRIANGLE);
  if (bytes > double(options.max_memory_bytes)) {
    throw ResourceLimit(cat(path, ": the build holds ", uint64_t(vertices), " vertices and ",
                            uint64_t(triangles), " triangles, which need about ", uint64_t(bytes),
                            " bytes, more than the memory limit of ", options.max_memory_bytes,
                            " bytes"));
  }
  TriMesh mesh;
  mesh.positions_mm.reserve(size_t(vertices));
  mesh.triangles.reserve(size_t(triangles));
  for (const auto& [object, placement] : items) objects.append(object->get(), placement, mesh, 0);
  return mesh;
}

void write_3mf(const std::string& path, const TriMesh& mesh, const ThreeMfInfo& info) {
  write_3mf(path, std::vector<ThreeMfObject>{{&mesh, info.object_name, ""}}, info);
}

void write_3mf(const std::string& path, const std::vector<ThreeMfObject>& parts, const ThreeMfInfo& info) {
  auto invalid = [&](const std::string& what) {
    throw InvalidInput(cat("cannot write '", path, "': ", what));
  };
  if (parts.empty()) invalid("no objects to write");
  std::vector<std::vector<NMR::MODELMESHVERTEX>> all_vertices;
  std::vector<std::vector<NMR::MODELMESHTRIANGLE>> all_triangles;
  for (const ThreeMfObject& part : parts) {
    const TriMesh& mesh = *part.mesh;
    if (mesh.positions_mm.size() > kMaxIndex || mesh.triangles.size() > kMaxIndex) {
      throw ResourceLimit(
          cat("cannot write '", path, "': more than ", kMaxIndex, " vertices or triangles"));
    }
    std::vector<NMR::MODELMESHVERTEX> vertices(mesh.positions_mm.size());
    for (size_t i = 0; i < vertices.size(); ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        float value = static_cast<float>(mesh.positions_mm[i][axis]);
        if (!(std::fabs(value) <= kMaxCoordinateMm)) {
          invalid(cat("vertex ", i, " has coordinate ", mesh.positions_mm[i][axis],
                      "; 3MF coordinates must be finite and within 1e9 mm"));
        }
        vertices[i].m_fPosition[axis] = value;
      }
    }
    std::vector<NMR::MODELMESHTRIANGLE> triangles(mesh.triangles.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        uint32_t v = mesh.triangles[t][k];
        if (v >= vertices.size()) {
          invalid(cat("triangle ", t, " refers to vertex ", v, " of ", vertices.size()));
        }
        triangles[t].m_nIndices[k] = v;
      }
    }
    if (has_control_character(part.name)) invalid("an object name contains a control character");
    const std::string& c = part.display_color;
    if (!c.empty() && (c.size() != 7 || c[0] != '#' ||
                       !std::all_of(c.begin() + 1, c.end(), [](char h) { return std::isxdigit(static_cast<unsigned char>(h)); })))
      invalid(cat("the display colour of '", part.name, "' is \"", c, "\", expected #rrggbb"));
    all_vertices.push_back(std::move(vertices));
    all_triangles.push_back(std::move(triangles));
  }
  // The 3MF core specification allows these names without a namespace; lib3mf 1.8 cannot declare
  // namespaces for others.
  static const std::set<std::string> kWellKnown = {
      "Title",  "Designer",     "Description",      "Copyright",  "LicenseTerms",
      "Rating", "CreationDate", "ModificationDate", "Application"};
  std::set<std::string> seen;
  for (const auto& [name, value] : info.metadata) {
    if (!kWellKnown.count(name)) invalid(cat("'", name, "' is not a 3MF metadata name"));
    if (!seen.insert(name).second) invalid(cat("metadata '", name, "' appears twice"));
    if (has_control_character(value)) {
      invalid(cat("metadata '", name, "' contains a control character"));
    }
  }
  // lib3mf gives every object, item and build a random UUID; deriving them from the content
  // keeps the package byte-identical for identical input (the zip entries carry no timestamps).
  uint64_t hash = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < parts.size(); ++i) {
    hash = fnv1a(hash, all_vertices[i].data(), all_vertices[i].size() * sizeof(NMR::MODELMESHVERTEX));
    hash = fnv1a(hash, all_triangles[i].data(), all_triangles[i].size() * sizeof(NMR::MODELMESHTRIANGLE));
    hash = fnv1a(hash, parts[i].name);
    hash = fnv1a(hash, parts[i].display_color);
  }
  for (const auto& [name, value] : info.metadata) hash = fnv1a(fnv1a(hash, name), value);

  const std::string where = cat("cannot write '", path, "'");
  // The model is written here rather than by lib3mf 1.8, whose writer prints coordinates with six
  // decimals, some off in the last one (89.57946014 as "89.579464"): every coordinate is printed in
  // the shortest form that reads back to the same float32, so the file holds the mesh exactly.
  std::string model;
  model.reserve(256 + [&] {
    size_t n = 0;
    for (size_t i = 0; i < parts.size(); ++i) n += 48 * all_vertices[i].size() + 48 * all_triangles[i].size();
    return n;
  }());
  model += "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
           "<model xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\" unit=\"millimeter\" "
           "xml:lang=\"en-US\" xmlns:p=\"http://schemas.microsoft.com/3dmanufacturing/production/2015/06\">\n";
  for (const auto& [name, value] : info.metadata)
    model += cat("\t<metadata name=\"", name, "\">", xml_escape(value), "</metadata>\n");
  model += "\t<resources>\n";
  char number[32];
  auto put_float = [&](float v) {
    auto result = std::to_chars(number, number + sizeof number, v);
    model.append(number, result.ptr);
  };
  auto put_index = [&](uint32_t v) {
    auto result = std::to_chars(number, number + sizeof number, v);
    model.append(number, result.ptr);
  };
  // Display colours: one base material per coloured part, in a group after the objects' ids.
  std::vector<int> material(parts.size(), -1);
  int materials = 0;
  for (size_t i = 0; i < parts.size(); ++i)
    if (!parts[i].display_color.empty()) material[i] = materials++;
  const size_t material_group = parts.size() + 1;
  if (materials > 0) {
    model += cat("\t\t<basematerials id=\"", material_group, "\">\n");
    for (size_t i = 0; i < parts.size(); ++i) {
      if (material[i] < 0) continue;
      std::string rgba = "#";
      for (size_t k = 1; k < 7; ++k) rgba += char(std::toupper(static_cast<unsigned char>(parts[i].display_color[k])));
      model += cat("\t\t\t<base name=\"", xml_escape(parts[i].name), "\" displaycolor=\"", rgba, "FF\" />\n");
    }
    model += "\t\t</basematerials>\n";
  }
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string property =
        material[i] < 0 ? std::string() : cat(" pid=\"", material_group, "\" pindex=\"", material[i], "\"");
    model += cat("\t\t<object id=\"", i + 1, "\" name=\"", xml_escape(parts[i].name), "\" type=\"model\"", property,
                 " p:UUID=\"", content_uuid(hash, i == 0 ? 1 : 2 + 2 * i), "\">\n\t\t\t<mesh>\n\t\t\t\t<vertices>\n");
    for (const NMR::MODELMESHVERTEX& v : all_vertices[i]) {
      model += "\t\t\t\t\t<vertex x=\"";
      put_float(v.m_fPosition[0]);
      model += "\" y=\"";
      put_float(v.m_fPosition[1]);
      model += "\" z=\"";
      put_float(v.m_fPosition[2]);
      model += "\" />\n";
    }
    model += "\t\t\t\t</vertices>\n\t\t\t\t<triangles>\n";
    for (const NMR::MODELMESHTRIANGLE& t : all_triangles[i]) {
      model += "\t\t\t\t\t<triangle v1=\"";
      put_index(t.m_nIndices[0]);
      model += "\" v2=\"";
      put_index(t.m_nIndices[1]);
      model += "\" v3=\"";
      put_index(t.m_nIndices[2]);
      model += "\" />\n";
    }
    model += "\t\t\t\t</triangles>\n\t\t\t</mesh>\n\t\t</object>\n";
  }
  model += cat("\t</resources>\n\t<build p:UUID=\"", content_uuid(hash, 3), "\">\n");
  for (size_t i = 0; i < parts.size(); ++i)
    model += cat("\t\t<item objectid=\"", i + 1, "\" p:UUID=\"", content_uuid(hash, i == 0 ? 2 : 3 + 2 * i), "\" />\n");
  model += "\t</build>\n</model>\n";
  static const std::string kContentTypes =
      "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      "<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">\n"
      "\t<Default Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\" />\n"
      "\t<Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\" />\n"
      "</Types>\n";
  static const std::string kRelationships =
      "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
      "<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">\n"
      "\t<Relationship Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\" "
      "Target=\"/3D/3dmodel.model\" Id=\"rel0\" />\n"
      "</Relationships>\n";

  // The package is made in memory (entries with a fixed date, so identical meshes give identical
  // bytes), then written to the file, every write checked; a partial file is removed.
  const std::string bytes = zip_archive({{"3D/3dmodel.model", model}, {"[Content_Types].xml", kContentTypes},
                                         {"_rels/.rels", kRelationships}},
                                        where);
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file) throw IoError(cat("cannot create '", path, "': ", std::strerror(errno)));
  bool written = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  int write_error = errno;
  if (std::fclose(file) != 0 && written) {
    written = false;
    write_error = errno;
  }
  if (!written) {
    // Remove the partial file, unless that is no regular file (say /dev/full).
    struct stat left;
    if (::stat(path.c_str(), &left) == 0 && S_ISREG(left.st_mode)) std::remove(path.c_str());
    throw IoError(where + ": " + std::strerror(write_error));
  }
}

}  // namespace lacuna
