#include "export/zip_archive.h"

#include <zip.h>

#include <cstdio>
#include <memory>

#include "errors.h"

namespace lacuna {

namespace {

// Adds the entries to an open archive and closes it; throws IoError (the archive discarded).
void fill_and_close(zip_t* archive, const std::vector<ZipEntry>& entries, const std::string& where) {
  auto fail = [&](const std::string& what) {
    const std::string message = what + ": " + zip_strerror(archive);
    zip_discard(archive);
    throw IoError(where + ": " + message);
  };
  for (const ZipEntry& entry : entries) {
    zip_source_t* source = entry.file.empty() ? zip_source_buffer(archive, entry.bytes.data(), entry.bytes.size(), 0)
                                              : zip_source_file(archive, entry.file.c_str(), 0, -1);
    if (!source) fail("cannot add " + entry.name);
    const zip_int64_t index = zip_file_add(archive, entry.name.c_str(), source, ZIP_FL_ENC_UTF_8);
    if (index < 0) {
      zip_source_free(source);
      fail("cannot add " + entry.name);
    }
    if (zip_set_file_compression(archive, zip_uint64_t(index), entry.deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE,
                                 entry.deflate ? 6 : 0) != 0 ||
        zip_file_set_dostime(archive, zip_uint64_t(index), 0, 0, 0) != 0)
      fail("cannot set up " + entry.name);
  }
  if (zip_close(archive) != 0) fail("cannot make the archive");
}

}  // namespace

std::string zip_archive(const std::vector<ZipEntry>& entries, const std::string& where) {
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, &error);
  if (!buffer) throw ResourceLimit(where + ": out of memory for the archive");
  zip_source_keep(buffer);
  std::unique_ptr<zip_source_t, void (*)(zip_source_t*)> owned(buffer, zip_source_free);
  zip_t* archive = zip_open_from_source(buffer, ZIP_TRUNCATE, &error);
  if (!archive) throw IoError(where + ": " + zip_error_strerror(&error));
  fill_and_close(archive, entries, where);
  std::string bytes;
  if (zip_source_open(buffer) != 0 || zip_source_seek(buffer, 0, SEEK_END) != 0)
    throw IoError(where + ": cannot read the archive back");
  const zip_int64_t size = zip_source_tell(buffer);
  bytes.resize(size_t(size < 0 ? 0 : size));
  if (size < 0 || zip_source_seek(buffer, 0, SEEK_SET) != 0 ||
      zip_source_read(buffer, bytes.data(), zip_uint64_t(bytes.size())) != size) {
    zip_source_close(buffer);
    throw IoError(where + ": cannot read the archive back");
  }
  zip_source_close(buffer);
  return bytes;
}

void write_zip_archive(const std::vector<ZipEntry>& entries, const std::string& path, const std::string& where) {
  int code = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &code);
  if (!archive) {
    zip_error_t error;
    zip_error_init_with_code(&error, code);
    const std::string message = zip_error_strerror(&error);
    zip_error_fini(&error);
    throw IoError(where + ": " + message);
  }
  fill_and_close(archive, entries, where);
}

}  // namespace lacuna
