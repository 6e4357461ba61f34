#include "rbsim/outputs.hpp"

#include <unistd.h>

#include <filesystem>

namespace rbsim {

namespace fs = std::filesystem;

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec)) return true;
  const fs::path ca = fs::weakly_canonical(a, ec);
  if (ec) return false;
  const fs::path cb = fs::weakly_canonical(b, ec);
  return !ec && ca == cb;
}

Status check_outputs(const std::vector<OutputPath>& outputs, const std::vector<std::string>& inputs,
                     bool overwrite, std::string_view overwrite_option) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const OutputPath& o = outputs[i];
    if (o.path.empty()) continue;
    const auto fail = [&](const std::string& rule) { return Error{o.option + " " + o.path + ": " + rule}; };
    for (const std::string& in : inputs) {
      if (same_file(o.path, in)) return fail("is an input of this command; refusing to write over it");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (!outputs[j].path.empty() && same_file(o.path, outputs[j].path))
        return fail("is also the output of " + outputs[j].option + "; give each output its own file");
    }
    std::error_code ec;
    const fs::file_status st = fs::status(o.path, ec);
    const bool exists = fs::exists(st);
    if (o.folder) {
      if (exists && !fs::is_directory(st)) return fail("exists and is not a folder");
      if (exists) {
        if (::access(o.path.c_str(), W_OK | X_OK) != 0) return fail("folder is not writable");
        continue;
      }
    } else if (exists) {
      if (fs::is_directory(st)) return fail("is a folder (give a file name)");
      if (!overwrite) return fail("exists (use " + std::string(overwrite_option) + " to replace it)");
    }
    // The file (or the folder to create) goes into its parent folder, which must exist and take it.
    fs::path parent = fs::path(o.path).parent_path();
    if (parent.empty()) parent = ".";
    if (!fs::is_directory(parent, ec)) {
      if (!o.folder) return fail("folder " + parent.string() + " does not exist");
      continue;  // a frame folder is created with its parents
    }
    if (::access(parent.c_str(), W_OK | X_OK) != 0)
      return fail("folder " + parent.string() + " is not writable");
  }
  return Ok{};
}

}  // namespace rbsim
