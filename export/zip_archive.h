// Zip archives made in memory (libzip) and written as one file: 3MF packages, SL1 archives, zipped
// layer stacks. Entries carry a fixed date, so identical entries give identical bytes.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace lacuna {

struct ZipEntry {
  std::string name;
  std::string_view bytes;  // the caller keeps them alive until the archive is made
  bool deflate = true;  // false: stored (already compressed data, such as PNG)
};

// The archive's bytes; `where` names it in messages (IoError, ResourceLimit).
std::string zip_archive(const std::vector<ZipEntry>& entries, const std::string& where);

}  // namespace lacuna
