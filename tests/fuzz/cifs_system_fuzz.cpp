// libFuzzer target: CIFS systems in JSON (recipe/cifs_system.h), as `lacuna cifs info` reads them.
#include <cstddef>
#include <cstdint>
#include <string>

#include "errors.h"
#include "recipe/cifs_system.h"
#include "recipe/json_fields.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const nlohmann::json value = lacuna::parse_json_text(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
    lacuna::cifs::parse_system(value, "fuzz.json", "");
  } catch (const lacuna::Error&) {
  }
  return 0;
}
