// libFuzzer target: Draco files as Lacuna reads them (export/draco.h: the declared counts checked
// against the budget, then Draco's decoder, then positions and faces validated).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "errors.h"
#include "export/draco.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lacuna::ReadOptions options;
    options.max_memory_bytes = uint64_t{1} << 30;  // libFuzzer's own limit is 2 GB
    lacuna::decode_draco(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.drc", options);
  } catch (const lacuna::Error&) {
  }
  return 0;
}
