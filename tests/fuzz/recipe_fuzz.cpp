// libFuzzer target: recipe text into option structs (recipe/recipe.h). Every input either parses or
// throws one of Lacuna's errors; anything else (a crash, a sanitizer report, another exception) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "errors.h"
#include "recipe/recipe.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lacuna::parse_recipe(std::string(reinterpret_cast<const char*>(data), size), "fuzz.json");
  } catch (const lacuna::Error&) {
  }
  return 0;
}
