// Zip archives made in memory (libzip) and written as one file: 3MF packages, SL1 archives, zipped
// layer stacks. Entries carry a fixed date, so identical entries give identical bytes.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace lacuna {

struct ZipEntry {
  ZipEntry() = default;
  ZipEntry(std::string entry_name, std::string_view entry_bytes, bool compress = true, std::string from_file = {})
      : name(std::move(entry_name)), bytes(entry_bytes), deflate(compress), file(std::move(from_file)) {}
  std::string name;
  std::string_view bytes;  // the caller keeps them alive until the archive is made
  bool deflate = true;  // false: stored (already compressed data, such as PNG)
  std::string file;     // when set, the entry's bytes are this file's (read as the archive is written);
                        // the entry takes the file's mode, which in-memory entries have as 0666
};

// The archive's bytes; `where` names it in messages (IoError, ResourceLimit).
std::string zip_archive(const std::vector<ZipEntry>& entries, const std::string& where);

// The same archive written straight to `path`, never whole in memory.
void write_zip_archive(const std::vector<ZipEntry>& entries, const std::string& path, const std::string& where);

}  // namespace lacuna
