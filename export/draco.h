// Draco (.drc) meshes: positions quantized on a grid fine enough for a given displacement and
// encoded with Draco's edgebreaker; decoding checks the counts the file declares against the memory
// budget before Draco allocates for them.
#pragma once

#include <string>
#include <string_view>

#include "export/mesh_io.h"
#include "geometry.h"

namespace lacuna {

// Draco quantizes each coordinate to (2^bits - 1) steps over the largest side of the mesh's box,
// so a decoded vertex moves by at most sqrt(3)/2 steps plus float32 rounding: that bound (mm).
double draco_move_bound_mm(const TriMesh& mesh, int bits);

// The fewest quantization bits (at most kMaxDracoBits) whose bound is within `max_move_mm`; 0 when
// even kMaxDracoBits would move vertices further.
constexpr int kMaxDracoBits = 30;
int draco_quantization_bits(const TriMesh& mesh, double max_move_mm);

// The mesh as a Draco file (positions only, one point per vertex, edgebreaker; `speed` is Draco's
// encoding and decoding speed, 0 the best compression and 10 the fastest). Byte-identical output
// for identical input. Throws ResourceLimit past 2^31 vertices.
std::string encode_draco(const TriMesh& mesh, int bits, int speed = 0);

// A Draco file's triangle mesh; `label` names it in messages (InvalidInput when it is not a Draco
// triangle mesh or is malformed, ResourceLimit when its declared counts exceed the budget).
TriMesh decode_draco(std::string_view bytes, const std::string& label, const ReadOptions& options = {});

}  // namespace lacuna
