// Files a client names by a uri (simulation_interfaces' Resource.uri: SpawnEntity's fragments,
// later LoadWorld's worlds), read only from folders the node was given on its command line
// (rbsim node --spawnables DIR). One policy for every uri, in one place:
//   - a path, or a file:// URI (file:///abs/path or file://localhost/abs/path, %XX decoded); any
//     other scheme is refused;
//   - a relative path is relative to a folder (the first, in the order given, that has it); an
//     absolute one must lie inside a folder (as given, or its canonical path);
//   - no '..' component, no NUL byte; below the folder every component is a directory and the last
//     a regular file, none a symbolic link (refused wherever it points, inside or out), no FIFO,
//     device, socket or directory at the end;
//   - read with a bound: at most `max_bytes`, the file opened without following a link and without
//     blocking, and checked again once open, so nothing swapped in between is read.
// Immutable once opened: read() and list() may run on any thread at once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/status.hpp"

namespace rbsim::node {

class ResourceFolders {
 public:
  // No folder: every uri is refused (NotAllowed).
  ResourceFolders() = default;
  // Each folder must be a directory; `what` names them in messages ("spawnables folder").
  static Result<ResourceFolders> open(const std::vector<std::string>& folders, std::string what);
  bool empty() const { return folders_.empty(); }
  // The folders as given, made absolute.
  std::vector<std::string> folders() const;

  enum class Refusal : std::uint8_t {
    None,
    NotAllowed,  // no folder, another scheme, outside every folder, '..', a symbolic link
    NotFound,    // no such file in any folder
    NotRegular,  // a directory, FIFO, device or socket
    TooLarge,    // more than max_bytes
    Unreadable,  // open or read failed (permissions, I/O)
  };
  struct Text {
    Refusal refusal = Refusal::None;
    std::string message;  // the refusal: "uri 'X': <the rule>"
    std::string path;     // the file read: its folder (as given) / the relative path
    std::string text;     // its bytes
  };
  // The file `uri` names, read whole (at most max_bytes), or why not.
  Text read(std::string_view uri, std::size_t max_bytes) const;

  struct Entry {
    std::string uri;   // as a client gives it back: the name, relative to its folder
    std::string path;  // its folder (as given) / the name
  };
  struct Listing {
    std::vector<Entry> files;  // by name; a name an earlier folder has is that folder's
    std::string refused;       // not empty: nothing listed, and why
  };
  // The regular files directly in the folders whose names end in `suffix` (".xml"), symbolic
  // links and the rest left out; refused past `max_files` such files or `max_entries` entries of
  // any kind in a folder.
  Listing list(std::string_view suffix, std::size_t max_files, std::size_t max_entries) const;

 private:
  struct Folder {
    std::string given;      // absolute, lexically normal
    std::string canonical;  // symbolic links resolved (the folder itself may be one)
  };
  std::vector<Folder> folders_;
  std::string what_;
  Text read_in(const Folder& folder, const std::vector<std::string>& parts, std::string_view uri,
               std::size_t max_bytes) const;
};

}  // namespace rbsim::node
