// Ctrl-C during a long call that released the GIL: Python's SIGINT handler only sets a flag, so the
// loop asks Python now and then (every 1,024 steps, re-taking the GIL for the question) and ends
// at a step boundary; the call then raises KeyboardInterrupt.
#pragma once

namespace rbsim::python {

class InterruptPoll {
 public:
  bool operator()();

 private:
  unsigned calls_ = 0;
  bool hit_ = false;
};

// DriverOptions::stop takes a plain function: it asks the poll this scope makes current on its
// thread.
class ScopedStop {
 public:
  explicit ScopedStop(InterruptPoll& poll);
  ~ScopedStop();
  ScopedStop(const ScopedStop&) = delete;
  ScopedStop& operator=(const ScopedStop&) = delete;
  static bool requested();

 private:
  InterruptPoll* previous_;
};

// Raises KeyboardInterrupt (with the GIL held).
[[noreturn]] void raise_interrupt();

}  // namespace rbsim::python
