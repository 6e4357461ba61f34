// The table of bad scenes in test/data/bad_scenes/MANIFEST (written by make_bad_scenes.py):
// each file and the one-line error it must produce. Shared by the scene and CLI tests.
#pragma once

#include <fstream>
#include <ostream>
#include <string>
#include <vector>

namespace rbsim::test {

struct BadScene {
  std::string file;   // name inside the bad_scenes directory
  int line = 0;       // 0: the message has no line number ("<path>: ...")
  bool exact = true;  // the message after "<path>:<line>: " is exactly `message`, else starts with it
  std::string message;

  // The start every error for this scene must have.
  std::string prefix(const std::string& path) const {
    return line > 0 ? path + ":" + std::to_string(line) + ": " : path + ": ";
  }
  // Empty when `error` (for the scene at `path`) is the expected one; else why not.
  std::string mismatch(const std::string& path, const std::string& error) const {
    const std::string head = prefix(path);
    if (error.find('\n') != std::string::npos) return "message is not one line";
    if (error.rfind(head, 0) != 0) return "message does not start with \"" + head + "\"";
    const std::string tail = error.substr(head.size());
    if (exact ? tail != message : tail.rfind(message, 0) != 0) {
      return std::string("expected ") + (exact ? "exactly" : "a message starting with") + " \"" + message +
             "\"";
    }
    return {};
  }
};

// Names the case in test output (instead of the bytes of the struct).
inline void PrintTo(const BadScene& b, std::ostream* os) {
  *os << b.file;
}

inline std::string trim_copy(const std::string& s) {
  const auto b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

inline std::vector<BadScene> read_bad_scene_manifest(const std::string& dir) {
  std::vector<BadScene> out;
  std::ifstream in(dir + "/MANIFEST");
  std::string row;
  while (std::getline(in, row)) {
    if (row.empty() || row[0] == '#') continue;
    std::vector<std::string> fields;
    std::size_t at = 0;
    for (int i = 0; i < 3; ++i) {
      const std::size_t bar = row.find(" | ", at);
      if (bar == std::string::npos) break;
      fields.push_back(trim_copy(row.substr(at, bar - at)));
      at = bar + 3;
    }
    if (fields.size() != 3) continue;
    out.push_back(BadScene{fields[0], std::stoi(fields[1]), fields[2] == "=", row.substr(at)});
  }
  return out;
}

}  // namespace rbsim::test
