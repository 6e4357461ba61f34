// The one way rbsim writes an output file: as a temporary beside its final path, moved into place by
// commit() (after an fsync, by default), so a reader never sees a half-written output and a run
// that fails leaves the old file as it was. open() makes the temporary unnamed (O_TMPFILE), so
// nothing of it survives any death of the process, SIGKILL included; commit() links it under
// `<path>.tmp.<pid>` and renames that over the path. Where the file system has no O_TMPFILE, and
// for external writers (open_external: the MCAP writer, whose killed temporary `rbsim log recover`
// saves, ffmpeg, gnuplot), the temporary is named `<path>.tmp.<pid>` from the start: destroying an
// uncommitted AtomicFile removes it, a killed process leaves it. Write errors name the file, the
// bytes written so far and the system's reason (ENOSPC, EDQUOT, EFBIG, EIO).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

#include "rbsim/status.hpp"

namespace rbsim {

class AtomicFile {
 public:
  // Fsync: the data is on disk before the rename (an output that must survive a power cut).
  // RenameOnly: the rename alone, which still keeps readers and a killed process from a half-written
  // file; for outputs made by the hundred (a render's frames), where an fsync each costs more
  // than the drawing.
  enum class Durability { Fsync, RenameOnly };

  AtomicFile() = default;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();

  // Creates the temporary and opens it for write() and stream().
  [[nodiscard]] Status open(const std::string& path);
  // Only names the temporary, for a writer that creates the file itself (the MCAP writer,
  // ffmpeg, gnuplot): it writes temp_path(), commit() moves that into place. Leftovers::Remove
  // first removes the temporaries `<path>.tmp.<pid>` that killed processes left for this path
  // (their pid no longer runs); a recording's (Keep) is what `rbsim log recover` saves.
  enum class Leftovers { Keep, Remove };
  void open_external(const std::string& path, Leftovers leftovers = Leftovers::Keep);

  [[nodiscard]] Status write(const void* data, std::size_t size);
  // The open temporary, for a library that writes through a FILE* (libpng); nullptr for an
  // external writer's file.
  std::FILE* stream() { return file_; }
  [[nodiscard]] Status commit(Durability durability = Durability::Fsync);  // flush, rename over path()
  void discard();  // removes the temporary; path() is left as it was

  const std::string& path() const { return path_; }
  // The named temporary; empty while an unnamed one (open() on O_TMPFILE) is being written.
  const std::string& temp_path() const { return temp_path_; }
  std::uint64_t bytes_written() const { return bytes_; }

 private:
  std::string path_, temp_path_;
  std::FILE* file_ = nullptr;
  bool pending_ = false;  // a temporary may exist and is ours to remove
  std::uint64_t bytes_ = 0;
};

}  // namespace rbsim
