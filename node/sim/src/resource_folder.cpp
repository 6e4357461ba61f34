// The one policy for files a client names by uri (resource_folder.hpp).
#include "resource_folder.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <set>
#include <utility>

#include "rbsim/counts.hpp"

namespace rbsim::node {

namespace {

namespace fs = std::filesystem;
using Refusal = ResourceFolders::Refusal;
using Text = ResourceFolders::Text;

// A file descriptor closed when it goes.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  Fd& operator=(Fd&& other) noexcept {
    std::swap(fd_, other.fd_);
    return *this;
  }
  int get() const { return fd_; }

 private:
  int fd_;
};

Text refuse(Refusal refusal, std::string_view uri, const std::string& rule) {
  Text t;
  t.refusal = refusal;
  t.message = "uri '" + std::string(uri) + "': " + rule;
  return t;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// The path a uri names: a path as it is, or a file:// URI's (file:///p, file://localhost/p; %XX
// decoded). Another scheme ("scheme://...") is an error naming the rule.
rbsim::Result<std::string> path_of(std::string_view uri) {
  const std::size_t colon = uri.find("://");
  const auto scheme_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '+' || c == '-' || c == '.';
  };
  const std::string_view scheme = colon == std::string_view::npos ? std::string_view{} : uri.substr(0, colon);
  if (scheme.empty() || std::isalpha(static_cast<unsigned char>(scheme[0])) == 0 ||
      !std::all_of(scheme.begin(), scheme.end(), scheme_char))
    return std::string(uri);  // a path
  std::string lower(scheme);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower != "file")
    return Error{"only a path or a file:// URI is read (not " + std::string(scheme) + "://)"};
  std::string_view rest = uri.substr(colon + 3);
  if (rest.starts_with("localhost/")) rest.remove_prefix(std::string_view("localhost").size());
  if (!rest.starts_with('/'))
    return Error{"a file:// URI names an absolute path on this host (file:///PATH or file://localhost/PATH)"};
  std::string path;
  for (std::size_t k = 0; k < rest.size(); ++k) {
    if (rest[k] != '%') {
      path += rest[k];
      continue;
    }
    const int hi = k + 2 < rest.size() ? hex_digit(rest[k + 1]) : -1;
    const int lo = hi >= 0 ? hex_digit(rest[k + 2]) : -1;
    if (lo < 0) return Error{"a '%' not followed by two hexadecimal digits"};
    path += static_cast<char>(hi * 16 + lo);
    k += 2;
  }
  return path;
}

// A path's components, "." and empty ones dropped; '..' and NUL bytes are errors.
rbsim::Result<std::vector<std::string>> components(std::string_view path, const std::string& what) {
  if (path.find('\0') != std::string_view::npos) return Error{"a NUL byte in the path"};
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string_view part = path.substr(start, end - start);
    if (part == "..") return Error{"'..' is not allowed (a uri names a file inside the " + what + ")"};
    if (!part.empty() && part != ".") parts.emplace_back(part);
    start = end + 1;
  }
  return parts;
}

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

std::string errno_text(int error) {
  return std::strerror(error);
}

// Reads the open regular file `fd` whole, at most `max_bytes` (one byte more tells it is larger).
Text read_bounded(int fd, std::string_view uri, const std::string& path, std::size_t max_bytes) {
  Text t;
  t.path = path;
  char buffer[64 * 1024];
  for (;;) {
    const std::size_t want = std::min(sizeof buffer, max_bytes + 1 - t.text.size());
    const ssize_t n = ::read(fd, buffer, want);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return refuse(Refusal::Unreadable, uri, path + ": read error: " + errno_text(errno));
    if (n == 0) break;
    t.text.append(buffer, static_cast<std::size_t>(n));
    if (t.text.size() > max_bytes)
      return refuse(Refusal::TooLarge, uri, path + " holds more than " + group_digits(max_bytes) + " bytes");
  }
  return t;
}

}  // namespace

rbsim::Result<ResourceFolders> ResourceFolders::open(const std::vector<std::string>& folders,
                                                     std::string what) {
  ResourceFolders out;
  out.what_ = std::move(what);
  for (const std::string& f : folders) {
    std::error_code ec;
    std::string given = fs::absolute(f, ec).lexically_normal().string();
    while (given.size() > 1 && given.ends_with('/')) given.pop_back();
    if (ec || !fs::is_directory(given, ec))
      return Error{out.what_ + " '" + f + "': not a directory" + (ec ? " (" + ec.message() + ")" : "")};
    const fs::path canonical = fs::canonical(given, ec);
    if (ec) return Error{out.what_ + " '" + f + "': " + ec.message()};
    out.folders_.push_back({given, canonical.string()});
  }
  return out;
}

std::vector<std::string> ResourceFolders::folders() const {
  std::vector<std::string> out;
  for (const Folder& f : folders_) out.push_back(f.given);
  return out;
}

// Walks `parts` down from the folder, one component at a time, never following a link (each
// looked at with fstatat before it is opened with O_NOFOLLOW, then the file checked once open).
ResourceFolders::Text ResourceFolders::read_in(const Folder& folder, const std::vector<std::string>& parts,
                                               std::string_view uri, std::size_t max_bytes) const {
  Fd dir(::open(folder.canonical.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (dir.get() < 0)
    return refuse(Refusal::Unreadable, uri,
                  "cannot open the " + what_ + " " + folder.given + ": " + errno_text(errno));
  std::string path = folder.given;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const char* name = parts[k].c_str();
    path += (path.ends_with('/') ? "" : "/") + parts[k];
    struct stat st {};
    if (::fstatat(dir.get(), name, &st, AT_SYMLINK_NOFOLLOW) != 0) {
      if (errno == ENOENT) return refuse(Refusal::NotFound, uri, "no such file: " + path);
      return refuse(Refusal::Unreadable, uri, path + ": " + errno_text(errno));
    }
    if (S_ISLNK(st.st_mode))
      return refuse(Refusal::NotAllowed, uri,
                    path + " is a symbolic link (refused wherever it points: give the file itself)");
    const bool last = k + 1 == parts.size();
    if (!last && !S_ISDIR(st.st_mode)) return refuse(Refusal::NotFound, uri, path + " is not a directory");
    if (last && !S_ISREG(st.st_mode))
      return refuse(Refusal::NotRegular, uri, path + " is " + kind_of(st.st_mode) + ", not a regular file");
    const int flags = last ? O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC
                           : O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC;
    Fd next(::openat(dir.get(), name, flags));
    if (next.get() < 0) {
      if (errno == ELOOP)
        return refuse(Refusal::NotAllowed, uri, path + " is a symbolic link (refused wherever it points)");
      return refuse(Refusal::Unreadable, uri, "cannot open " + path + ": " + errno_text(errno));
    }
    dir = std::move(next);
  }
  // Checked again on the open file: what was looked at may have been replaced since.
  struct stat opened {};
  if (::fstat(dir.get(), &opened) != 0 || !S_ISREG(opened.st_mode))
    return refuse(Refusal::NotRegular, uri, path + " is not a regular file");
  if (opened.st_size > 0 && static_cast<std::uintmax_t>(opened.st_size) > max_bytes)
    return refuse(Refusal::TooLarge, uri,
                  path + " holds " + group_digits(static_cast<std::uint64_t>(opened.st_size)) +
                      " bytes, more than " + group_digits(max_bytes));
  return read_bounded(dir.get(), uri, path, max_bytes);
}

ResourceFolders::Text ResourceFolders::read(std::string_view uri, std::size_t max_bytes) const {
  if (folders_.empty()) return refuse(Refusal::NotAllowed, uri, "no " + what_ + " was given");
  const rbsim::Result<std::string> path = path_of(uri);
  if (!path) return refuse(Refusal::NotAllowed, uri, path.error().message);
  const rbsim::Result<std::vector<std::string>> parts = components(path.value(), what_);
  if (!parts) return refuse(Refusal::NotAllowed, uri, parts.error().message);
  if (parts.value().empty()) return refuse(Refusal::NotFound, uri, "names no file");
  std::string list;
  for (const Folder& f : folders_) list += (list.empty() ? "" : ", ") + f.given;
  if (!path.value().starts_with('/')) {  // relative: the first folder that has it
    for (const Folder& f : folders_) {
      Text t = read_in(f, parts.value(), uri, max_bytes);
      if (t.refusal != Refusal::NotFound) return t;
      if (folders_.size() == 1) return t;
    }
    return refuse(Refusal::NotFound, uri, "no such file in the " + what_ + " (" + list + ")");
  }
  // Absolute: inside a folder, as given or as its canonical path.
  for (const Folder& f : folders_) {
    for (const std::string* root : {&f.given, &f.canonical}) {
      const rbsim::Result<std::vector<std::string>> under = components(*root, what_);
      if (!under || under.value().size() > parts.value().size() ||
          !std::equal(under.value().begin(), under.value().end(), parts.value().begin()))
        continue;
      const std::vector<std::string> rest(
          parts.value().begin() + static_cast<std::ptrdiff_t>(under.value().size()), parts.value().end());
      if (rest.empty()) return refuse(Refusal::NotRegular, uri, "is the " + what_ + " itself, a directory");
      return read_in(f, rest, uri, max_bytes);
    }
  }
  return refuse(Refusal::NotAllowed, uri, "outside the " + what_ + " (" + list + ")");
}

ResourceFolders::Listing ResourceFolders::list(std::string_view suffix, std::size_t max_files,
                                               std::size_t max_entries) const {
  Listing out;
  std::set<std::string, std::less<>> earlier;  // every name of the folders before: theirs
  for (const Folder& f : folders_) {
    std::vector<Entry> here;
    std::vector<std::string> names;
    std::error_code ec;
    for (fs::directory_iterator it(f.canonical, ec), end; !ec && it != end; it.increment(ec)) {
      if (names.size() == max_entries)
        return Listing{
            {},
            "the " + what_ + " " + f.given + " holds more than " + group_digits(max_entries) + " entries"};
      std::string name = it->path().filename().string();
      names.push_back(name);
      std::error_code type_ec;
      const fs::file_type type = it->symlink_status(type_ec).type();
      if (type_ec || type != fs::file_type::regular || name.size() <= suffix.size() ||
          !name.ends_with(suffix) || earlier.contains(name))
        continue;
      if (out.files.size() + here.size() == max_files)
        return Listing{{},
                       "the " + what_ + " holds more than " + group_digits(max_files) + " " +
                           std::string(suffix) + " files"};
      here.push_back({name, f.given + (f.given.ends_with('/') ? "" : "/") + name});
    }
    if (ec) return Listing{{}, "cannot list the " + what_ + " " + f.given + ": " + ec.message()};
    std::sort(here.begin(), here.end(), [](const Entry& a, const Entry& b) { return a.uri < b.uri; });
    out.files.insert(out.files.end(), std::make_move_iterator(here.begin()),
                     std::make_move_iterator(here.end()));
    earlier.insert(names.begin(), names.end());
  }
  return out;
}

}  // namespace rbsim::node
