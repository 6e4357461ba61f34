// Internals of the Python extension `rbsim._rbsim`: each file binds one job (world.cpp the Scene
// and World, data.cpp the run, the recording reader and the check) into the one module (module.cpp).
#pragma once

#include <nanobind/nanobind.h>

#include <string>

#include "rbsim/status.hpp"

namespace rbsim::python {

namespace nb = nanobind;

// The Python exception classes of rbsim/_errors.py, raised from C++ with their attributes.
[[noreturn]] void raise_error(const std::string& message);  // rbsim.Error
[[noreturn]] void raise_scene_error(const std::string& path, const std::string& message);
[[noreturn]] void raise_divergence(const std::string& message);
// Status -> nothing, or rbsim.Error with its message.
void check(const Status& status);

// A path argument as rbsim's C++ API takes it: str or os.PathLike.
std::string fs_path(nb::handle path);

void bind_world(nb::module_& m);
void bind_data(nb::module_& m);

}  // namespace rbsim::python
