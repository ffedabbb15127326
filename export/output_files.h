// All-or-nothing output: files are written under temporary names next to their final names and
// renamed only when the whole job succeeded; otherwise every temporary file is removed, and files
// that existed before are left untouched. An output folder is locked while a job writes into it, and
// what an interrupted job was writing can be removed from a signal-handling thread.
#pragma once

#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

namespace lacuna {

class OutputTransaction {
 public:
  OutputTransaction() = default;
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  ~OutputTransaction();  // rolls back unless committed

  // Registers a final path and returns the temporary path to write instead (same directory):
  // "<dir>/.<name>.tmp-<pid>-<counter>".
  std::string stage(const std::string& final_path);
  // Renames every staged file to its final name. Throws IoError if a rename fails (the files
  // already renamed stay; the rest are removed). The temporaries are untracked once all are renamed: an
  // interrupt meanwhile removes those not yet renamed (a renamed one is gone under its temporary name).
  void commit();
  // Removes every staged temporary file.
  void rollback();
  // `message` with every staged temporary's path replaced by its final path: errors of the writers
  // and readers name the files the user asked for, not their hidden temporaries.
  std::string with_final_names(std::string message) const {
    for (const Entry& e : entries_)
      for (size_t at = message.find(e.temp_path); at != std::string::npos;
           at = message.find(e.temp_path, at + e.final_path.size()))
        message.replace(at, e.temp_path.size(), e.final_path);
    return message;
  }

 private:
  struct Entry {
    std::string temp_path;
    std::string final_path;
  };
  std::vector<Entry> entries_;
  std::unordered_set<std::string> finals_;       // the final paths staged, to refuse one written twice
  std::unordered_set<std::string> temporaries_;  // their temporaries, untracked in one pass (commit and rollback
                                                 // allocate nothing: rollback runs in the destructor)
  bool done_ = false;
};

// Writes `bytes` as the whole file `path` (created or truncated). Throws IoError naming it on failure.
void write_whole_file(const std::string& path, const std::string& bytes);

// A scratch file a job writes beside its outputs and never keeps (a spool): an interrupt removes it
// as it removes the job's temporaries, and so does the destructor.
class ScratchFile {
 public:
  explicit ScratchFile(std::string path);
  ~ScratchFile();
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Writes a whole text file through a temporary name and a rename. Throws IoError on failure.
void write_text_file_atomically(const std::string& path, const std::string& text);

// An output folder held for one job: created when missing (with its missing parents), locked with
// flock() on the hidden file ".lacuna.lock" inside it for as long as this object lives, and cleared of
// the temporaries that processes no longer running left there (killed runs). Unless keep() was
// called, the folders it created are removed again when it is destroyed (only if they are empty).
class OutputFolder {
 public:
  // Throws IoError when the path exists and is not a folder or cannot be created, ResourceLimit when
  // another job holds the folder (the message names its process).
  explicit OutputFolder(const std::string& path);
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;
  ~OutputFolder();

  // The job succeeded: the folders stay.
  void keep() { keep_ = true; }
  // Temporaries of processes no longer running that were removed when the folder was taken.
  size_t stale_removed() const { return stale_removed_; }

 private:
  std::string path_;
  std::string lock_path_;
  std::vector<std::string> created_;  // folders made here, outermost first
  int lock_fd_ = -1;
  bool keep_ = false;
  size_t stale_removed_ = 0;
};

// The file name of the lock file inside an output folder.
constexpr const char* kOutputLockName = ".lacuna.lock";

// Whether `name` is a temporary of OutputTransaction (".<name>.tmp-<pid>-<k>"); sets `pid` to its writer's.
bool is_output_temporary(const std::string& name, long* pid = nullptr);

// Removes every temporary file, lock file and created folder that the output transactions and
// folders of this process hold now (files first, then folders, innermost first). For a front end's
// handler of SIGINT or SIGTERM, called from an ordinary thread (not inside a signal handler) just
// before the process ends; the objects holding them must not be used afterwards.
void remove_unfinished_outputs();

}  // namespace lacuna
