// The one way rbsim writes an output file: as a temporary beside its final path, moved into place by
// commit() (after an fsync, by default), so a reader never sees a half-written output and a run
// that fails leaves the old file as it was. The temporary is unnamed (O_TMPFILE) where the file
// system allows, so nothing of it survives any death of the process, SIGKILL included; commit()
// links it under `<path>.tmp.<pid>` and renames that over the path. An external writer (our MCAP
// writer, ffmpeg, gnuplot: open_external) reaches the unnamed file by its /proc path. The one
// temporary that is named from the start is a recording's (Leftovers::Keep), which `rbsim log
// recover` saves after a kill; elsewhere a file system without O_TMPFILE gets a named temporary
// too, removed by destroying an uncommitted AtomicFile or, after a kill, by the next writer of that
// output. Write errors name the file, the bytes written so far and the system's reason (ENOSPC,
// EDQUOT, EFBIG, EIO).
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

  // Creates the temporary, with permissions `mode` less the umask (0600: a private key), and
  // opens it for write() and stream().
  [[nodiscard]] Status open(const std::string& path, unsigned mode = 0666);
  // For a writer that opens the file itself by a path (the MCAP writer, ffmpeg, gnuplot): it
  // writes writer_path() (opening it truncates), commit() moves that into place. Keep: the
  // temporary is named `<path>.tmp.<pid>` from the start, and a killed writer's stays for
  // `rbsim log recover` (a recording). Remove: the temporary is unnamed where the file system
  // allows (named otherwise), and the named temporaries that killed processes left for this path
  // (their pid no longer runs) are removed first.
  enum class Leftovers { Keep, Remove };
  void open_external(const std::string& path, Leftovers leftovers = Leftovers::Keep);
  // The path an external writer opens: the named temporary, or /proc/PID/fd/N of the unnamed one.
  std::string writer_path() const;

  [[nodiscard]] Status write(const void* data, std::size_t size);
  // The open temporary, for a library that writes through a FILE* (libpng); nullptr for an
  // external writer's file.
  std::FILE* stream() { return external_ ? nullptr : file_; }
  [[nodiscard]] Status commit(Durability durability = Durability::Fsync);  // flush, rename over path()
  void discard();  // removes the temporary; path() is left as it was

  const std::string& path() const { return path_; }
  // The named temporary; empty while an unnamed one (O_TMPFILE) is being written.
  const std::string& temp_path() const { return temp_path_; }
  std::uint64_t bytes_written() const { return bytes_; }

 private:
  std::string path_, temp_path_;
  std::FILE* file_ = nullptr;
  bool pending_ = false;   // a temporary may exist and is ours to remove
  bool external_ = false;  // another writer fills the temporary; file_, if any, only holds it open
  std::uint64_t bytes_ = 0;
};

// A path by which a process this one starts reaches the open file `fd`, named or not:
// /proc/PID/fd/N (opening it opens the same file; valid while this process holds fd open).
std::string open_file_path(int fd);

}  // namespace rbsim
