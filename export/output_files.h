// All-or-nothing output: files are written under temporary names next to their final names and
// renamed only when the whole job succeeded; otherwise every temporary file is removed, and files
// that existed before are left untouched.
#pragma once

#include <string>
#include <vector>

namespace lacuna {

class OutputTransaction {
 public:
  OutputTransaction() = default;
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  ~OutputTransaction();  // rolls back unless committed

  // Registers a final path and returns the temporary path to write instead (same directory).
  std::string stage(const std::string& final_path);
  // Renames every staged file to its final name. Throws IoError if a rename fails (the files
  // already renamed stay; the rest are removed).
  void commit();
  // Removes every staged temporary file.
  void rollback();

 private:
  struct Entry {
    std::string temp_path;
    std::string final_path;
  };
  std::vector<Entry> entries_;
  bool done_ = false;
};

// Writes a whole text file through a temporary name and a rename. Throws IoError on failure.
void write_text_file_atomically(const std::string& path, const std::string& text);

}  // namespace lacuna
