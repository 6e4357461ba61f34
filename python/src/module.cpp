// rbsim._rbsim: the extension module of the Python package (python/rbsim/__init__.py re-exports
// it). Errors are the classes of rbsim/_errors.py, so Python code can catch them by name and read
// their fields.
#include <nanobind/stl/string.h>

#include "bindings.hpp"
#include "interrupt.hpp"
#include "rbsim/core.hpp"

namespace rbsim::python {

namespace {

nb::object error_class(const char* name) {
  return nb::module_::import_("rbsim._errors").attr(name);
}

[[noreturn]] void raise_object(nb::object error) {
  PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
  throw nb::python_error();
}

}  // namespace

void raise_error(const std::string& message) {
  raise_object(error_class("Error")(message));
}

void raise_divergence(const std::string& message) {
  raise_object(error_class("DivergenceError")(message));
}

// The loader's one-line message is "<file>:<line>: <rule>", or for an attribute
// "<file>:<line>: <node> attribute 'a': <rule>" (rbsim/scene.hpp): its parts become the error's
// fields (line 0 and empty node or attribute where the message has none, e.g. a missing file).
void raise_scene_error(const std::string& path, const std::string& message) {
  std::string rest = message;
  long line = 0;
  std::string node, attribute;
  if (rest.rfind(path + ":", 0) == 0) {
    rest.erase(0, path.size() + 1);
    std::size_t digits = 0;
    while (digits < rest.size() && rest[digits] >= '0' && rest[digits] <= '9') ++digits;
    if (digits > 0 && digits < 10 && rest.compare(digits, 2, ": ") == 0) {
      line = std::stol(rest.substr(0, digits));
      rest.erase(0, digits + 2);
    } else if (rest.rfind(" ", 0) == 0) {
      rest.erase(0, 1);
    }
  }
  if (!rest.empty() && rest.front() == '<') {
    const std::size_t close = rest.find("> attribute '");
    if (close != std::string::npos) {
      const std::size_t name_start = close + 13;
      const std::size_t name_end = rest.find("': ", name_start);
      if (name_end != std::string::npos) {
        node = rest.substr(1, close - 1);
        attribute = rest.substr(name_start, name_end - name_start);
        rest.erase(0, name_end + 3);
      }
    }
  }
  raise_object(error_class("SceneError")(message, path, line, node, attribute, rest));
}

void check(const Status& status) {
  if (!status) raise_error(status.error().message);
}

std::string fs_path(nb::handle path) {
  nb::object fspath = nb::module_::import_("os").attr("fspath")(path);
  if (!nb::isinstance<nb::str>(fspath)) throw nb::type_error("expected a str path, not bytes");
  return nb::cast<std::string>(fspath);
}

}  // namespace rbsim::python

NB_MODULE(_rbsim, m) {
  m.doc() =
      "rbsim's simulator, recordings and checks (the C++ library, bound with nanobind). Import the "
      "package, `import rbsim`, rather than this module.";
  m.attr("__version__") = rbsim::version();
  // A call that does nothing: what nanobind itself costs per call (scripts/bench-python).
  m.def("_noop", [] {});
  rbsim::python::bind_world(m);
  rbsim::python::bind_data(m);
}

namespace rbsim::python {

bool InterruptPoll::operator()() {
  if (hit_ || (++calls_ & 1023u) != 0) return hit_;
  nb::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) {
    PyErr_Clear();  // raised again by raise_interrupt() once the outputs are complete
    hit_ = true;
  }
  return hit_;
}

namespace {
thread_local InterruptPoll* current_poll = nullptr;
}

ScopedStop::ScopedStop(InterruptPoll& poll) : previous_(current_poll) {
  current_poll = &poll;
}
ScopedStop::~ScopedStop() {
  current_poll = previous_;
}
bool ScopedStop::requested() {
  return current_poll != nullptr && (*current_poll)();
}

void raise_interrupt() {
  PyErr_SetNone(PyExc_KeyboardInterrupt);
  throw nb::python_error();
}

}  // namespace rbsim::python
