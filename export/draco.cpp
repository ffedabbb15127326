#include "export/draco.h"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>

#include "errors.h"

namespace lacuna {
namespace {

// What decoding needs per face and per point, Draco's corner table and attribute included, with
// the TriMesh it becomes (measured order of magnitude, rounded up).
constexpr double kDecodeBytesPerFace = 100;
constexpr double kDecodeBytesPerPoint = 100;

struct Box {
  float min[3], max[3];
};

Box float_box(const TriMesh& mesh) {
  Box b{{HUGE_VALF, HUGE_VALF, HUGE_VALF}, {-HUGE_VALF, -HUGE_VALF, -HUGE_VALF}};
  for (const Vec3d& p : mesh.positions_mm) {
    const float c[3] = {float(p.x), float(p.y), float(p.z)};
    for (int k = 0; k < 3; ++k) {
      b.min[k] = std::min(b.min[k], c[k]);
      b.max[k] = std::max(b.max[k], c[k]);
    }
  }
  return b;
}

// Reads a little-endian base-128 varint as Draco writes it (at most 5 bytes for 32 bits).
std::optional<uint64_t> varint(std::string_view bytes, size_t& at) {
  uint64_t value = 0;
  for (int shift = 0; shift < 35 && at < bytes.size(); shift += 7) {
    const auto byte = uint8_t(bytes[at++]);
    value |= uint64_t(byte & 0x7f) << shift;
    if (!(byte & 0x80)) return value;
  }
  return std::nullopt;
}

struct DeclaredCounts {
  uint64_t faces = 0, points = 0;
};

// The face and point counts a version 2.2 mesh without metadata (the caller has checked both)
// declares in its connectivity header (Draco bitstream specification: the 11-byte header, then for
// sequential encoding num_faces and num_points, for edgebreaker the traversal type,
// num_encoded_vertices and num_faces); nothing when they are cut off or the method is unknown.
std::optional<DeclaredCounts> declared_counts(std::string_view bytes) {
  constexpr size_t kHeader = 11;
  const auto method = uint8_t(bytes[8]);
  size_t at = kHeader;
  DeclaredCounts counts;
  if (method == 0) {
    auto faces = varint(bytes, at), points = varint(bytes, at);
    if (!faces || !points) return std::nullopt;
    counts = {*faces, *points};
  } else if (method == 1) {
    ++at;  // traversal type
    auto vertices = varint(bytes, at), faces = varint(bytes, at);
    if (!vertices || !faces) return std::nullopt;
    counts = {*faces, *vertices};
  } else {
    return std::nullopt;
  }
  return counts;
}

// What Draco's grid spans: the largest side of the float box, and the largest coordinate.
struct GridSpan {
  double range = 0, largest = 0;
};

GridSpan grid_span(const TriMesh& mesh) {
  const Box b = float_box(mesh);
  GridSpan g;
  for (int k = 0; k < 3; ++k) {
    g.range = std::max(g.range, double(b.max[k]) - double(b.min[k]));
    g.largest = std::max({g.largest, std::fabs(double(b.min[k])), std::fabs(double(b.max[k]))});
  }
  if (!(g.range > 0)) g.range = 1;  // Draco's own choice for a flat box
  return g;
}

double move_bound(const GridSpan& g, int bits) {
  const double step = g.range / double((uint64_t{1} << bits) - 1);
  // Half a step from rounding to the grid; float32 rounding of the input, of the dequantized
  // offset and of its sum with the box's corner: a few units in the last place of the largest value.
  const double ulp = g.largest * std::ldexp(1.0, -23);
  return std::sqrt(3.0) * (0.5 * step + 4 * ulp);
}

}  // namespace

double draco_move_bound_mm(const TriMesh& mesh, int bits) { return move_bound(grid_span(mesh), bits); }

int draco_quantization_bits(const TriMesh& mesh, double max_move_mm) {
  const GridSpan g = grid_span(mesh);
  for (int bits = 1; bits <= kMaxDracoBits; ++bits)
    if (move_bound(g, bits) <= max_move_mm) return bits;
  return 0;
}

std::string encode_draco(const TriMesh& mesh, int bits, int speed) {
  if (mesh.positions_mm.size() > uint64_t(std::numeric_limits<int32_t>::max()) ||
      mesh.triangles.size() > uint64_t(std::numeric_limits<int32_t>::max()) / 3)
    throw ResourceLimit("a Draco file holds at most 2^31 vertices and 715 827 882 triangles");
  if (bits < 1 || bits > kMaxDracoBits) throw InvalidInput("Draco quantization needs 1 to 30 bits");
  if (speed < 0 || speed > 10) throw InvalidInput("Draco's speed runs from 0 to 10");
  draco::Mesh out;
  const auto points = uint32_t(mesh.positions_mm.size());
  out.set_num_points(points);
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, sizeof(float) * 3, 0);
  draco::PointAttribute* attribute = out.attribute(out.AddAttribute(position, true, points));
  for (uint32_t i = 0; i < points; ++i) {
    const Vec3d& p = mesh.positions_mm[i];
    const float value[3] = {float(p.x), float(p.y), float(p.z)};
    attribute->SetAttributeValue(draco::AttributeValueIndex(i), value);
  }
  out.SetNumFaces(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (uint32_t v : tri)
      if (v >= points) throw InvalidInput("triangle " + std::to_string(t) + " refers to a missing vertex");
    out.SetFace(draco::FaceIndex(uint32_t(t)),
                {draco::PointIndex(tri[0]), draco::PointIndex(tri[1]), draco::PointIndex(tri[2])});
  }
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, bits);
  encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
  encoder.SetSpeedOptions(speed, speed);
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeMeshToBuffer(out, &buffer);
  if (!status.ok()) throw InternalError(std::string("Draco could not encode the mesh: ") + status.error_msg());
  return std::string(buffer.data(), buffer.size());
}

TriMesh decode_draco(std::string_view bytes, const std::string& label, const ReadOptions& options) {
  if (bytes.size() < 11 || bytes.substr(0, 5) != "DRACO")
    throw InvalidInput(label + ": not a Draco file (it does not start with \"DRACO\")");
  if (uint8_t(bytes[7]) != 1) throw InvalidInput(label + ": a Draco point cloud, not a triangle mesh");
  // Older bitstreams store their counts elsewhere, and Draco allocates for them before checking them
  // against the data (found by fuzzing: a 100-byte version 1.x file asked for gigabytes); metadata
  // comes before the counts. Only what can be bounded first is decoded.
  if (uint8_t(bytes[5]) != 2 || uint8_t(bytes[6]) != 2)
    throw InvalidInput(label + ": Draco bitstream version " + std::to_string(uint8_t(bytes[5])) + "." +
                       std::to_string(uint8_t(bytes[6])) + "; this reader takes version 2.2 (Draco 1.4 and later)");
  if (uint8_t(bytes[10]) & 0x80)
    throw InvalidInput(label + ": the Draco file carries metadata; this reader takes meshes without (re-encode it "
                       "with draco_encoder)");
  const std::optional<DeclaredCounts> counts = declared_counts(bytes);
  if (!counts) throw InvalidInput(label + ": malformed Draco header (no face and vertex counts)");
  const double need = kDecodeBytesPerFace * double(counts->faces) + kDecodeBytesPerPoint * double(counts->points);
  if (need > double(options.max_memory_bytes)) {
    throw ResourceLimit(label + ": " + std::to_string(counts->faces) + " triangles and " +
                        std::to_string(counts->points) + " vertices need about " +
                        message_number(need / double(uint64_t{1} << 30)) +
                        " GiB to decode, more than the memory limit of " +
                        message_number(double(options.max_memory_bytes) / double(uint64_t{1} << 30)) + " GiB");
  }
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) throw InvalidInput(label + ": malformed Draco mesh (" + decoded.status().error_msg_string() + ")");
  const std::unique_ptr<draco::Mesh> in = std::move(decoded).value();
  const draco::PointAttribute* position = in->GetNamedAttribute(draco::GeometryAttribute::POSITION);
  // Read as bytes (no typed loads from Draco's buffer, which a malformed file can misalign), each
  // within the buffer.
  if (!position || position->num_components() != 3 || position->data_type() != draco::DT_FLOAT32 ||
      position->byte_stride() != 3 * int64_t(sizeof(float)) || !position->buffer() || position->byte_offset() < 0)
    throw InvalidInput(label + ": the Draco mesh has no positions of three 32-bit floats");
  const draco::DataBuffer& values = *position->buffer();
  TriMesh mesh;
  mesh.positions_mm.resize(in->num_points());
  for (uint32_t i = 0; i < in->num_points(); ++i) {
    float value[3];
    const draco::AttributeValueIndex index = position->mapped_index(draco::PointIndex(i));
    const uint64_t at = uint64_t(position->byte_offset()) + uint64_t(sizeof value) * uint64_t(index.value());
    if (index == draco::kInvalidAttributeValueIndex || at + sizeof value > uint64_t(values.data_size()))
      throw InvalidInput(label + ": vertex " + std::to_string(i) + " has no position");
    std::memcpy(value, values.data() + at, sizeof value);
    for (float c : value)
      if (!std::isfinite(c)) throw InvalidInput(label + ": vertex " + std::to_string(i) + " is not finite");
    mesh.positions_mm[i] = Vec3d{value[0], value[1], value[2]};
  }
  mesh.triangles.resize(in->num_faces());
  for (uint32_t f = 0; f < in->num_faces(); ++f) {
    const draco::Mesh::Face& face = in->face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      if (face[k].value() >= in->num_points())
        throw InvalidInput(label + ": triangle " + std::to_string(f) + " refers to a missing vertex");
      mesh.triangles[f][size_t(k)] = face[k].value();
    }
  }
  return mesh;
}

// Declared in mesh_io.cpp, which has checked that the file exists, is regular and is not empty.
TriMesh read_draco(const std::string& path, const ReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open '" + path + "': " + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const auto size = uint64_t(std::max<std::streamoff>(in.tellg(), 0));
  if (size > options.max_memory_bytes)
    throw ResourceLimit(path + ": a Draco file of " + std::to_string(size) + " bytes is more than the memory limit");
  std::string bytes(size, '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), std::streamsize(size))) throw IoError("cannot read '" + path + "'");
  return decode_draco(bytes, path, options);
}

}  // namespace lacuna
