// Running rbsim as a child process with a time limit, and small file helpers, for the tests.
#pragma once

#include <chrono>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace rbsim::test {

struct Outcome {
  int exit_code = -1;  // exit status, or -1 if killed by a signal / the timeout
  int signal = 0;      // the signal that ended it, if any
  bool timed_out = false;
  std::string out, err;  // everything written to stdout and stderr
  std::vector<std::string> err_lines() const;
};
// "exit N signal S", then stdout and stderr: for test failure messages.
std::ostream& operator<<(std::ostream& os, const Outcome& o);

// Runs `exe args...` with stdout and stderr captured; kills it after `timeout`. `extra_env`
// ("NAME=value") is added to this process's environment for the child.
Outcome run_process(const std::string& exe, const std::vector<std::string>& args,
                    std::chrono::milliseconds timeout = std::chrono::seconds(60),
                    const std::vector<std::string>& extra_env = {});

// Runs the rbsim binary under test.
Outcome rbsim(const std::vector<std::string>& args,
              std::chrono::milliseconds timeout = std::chrono::seconds(60));

std::string read_text(const std::filesystem::path& path);
void write_text(const std::filesystem::path& path, const std::string& text);  // creates its folder
std::vector<std::string> lines_of(const std::string& text);                   // without the newlines
std::vector<std::string> split(const std::string& line, char sep);

// A fresh directory, removed with its contents at the end of the scope.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace rbsim::test
