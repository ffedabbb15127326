// libFuzzer target: the mesh readers (export/mesh_io.h). The format comes from the first byte (STL,
// OBJ, PLY, 3MF), the rest is the file; readers take paths, so it goes through a file in /tmp.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "errors.h"
#include "export/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* kExtensions[] = {".stl", ".obj", ".ply", ".3mf"};
  const std::string path = "/tmp/lacuna-fuzz-" + std::to_string(::getpid()) + kExtensions[data[0] % 4];
  if (std::FILE* file = std::fopen(path.c_str(), "wb")) {
    std::fwrite(data + 1, 1, size - 1, file);
    std::fclose(file);
  }
  try {
    lacuna::ReadOptions options;
    options.max_memory_bytes = uint64_t{1} << 30;  // libFuzzer's own limit is 2 GB
    lacuna::read_mesh(path, options);
  } catch (const lacuna::Error&) {
  }
  std::remove(path.c_str());
  return 0;
}
