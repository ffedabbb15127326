#include "cli/exit_codes.h"

#include <new>

#include "errors.h"

namespace lacuna {

int exit_code(const std::exception& error) {
  if (dynamic_cast<const InvalidInput*>(&error) || dynamic_cast<const IoError*>(&error)) return kExitBadInput;
  if (dynamic_cast<const ResourceLimit*>(&error) || dynamic_cast<const std::bad_alloc*>(&error)) return kExitResourceLimit;
  if (dynamic_cast<const CheckFailed*>(&error)) return kExitCheckFailed;
  return kExitInternal;
}

}  // namespace lacuna
