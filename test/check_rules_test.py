#!/usr/bin/env python3
"""check_modules.py and check_sizes.py on small source trees made here: a clean tree passes, each
deliberate break of a rule fails with its message, and the allow-list ratchets.

    check_rules_test.py   # unittest; exit 1 on a failure
"""
import pathlib
import subprocess
import sys
import tempfile
import textwrap
import unittest

HERE = pathlib.Path(__file__).resolve().parent


def function(name, lines):
    """A clang-formatted C++ function of exactly `lines` lines, with a lambda, a string holding a
    brace and a comment holding one (none of which may end it early)."""
    body = ["  int n = 0;", '  const char* s = "}";', "  // }", "  auto f = [&](int k) {", "    return k + 1;", "  };"]
    body += ["  n = f(n);"] * (lines - len(body) - 3)
    return "\n".join([f"int {name}(int x) {{"] + body + ["  return n + x + (s[0] == '}');", "}"]) + "\n"


class Tree:
    """A temporary source tree: the modules core (sim_core), mcap, recordings, check and node, each with a
    public header, and whatever files a test adds."""

    def __init__(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.root = pathlib.Path(self.tmp.name)
        for folder, header in [("sim_core", "core"), ("tools/mcap", "mcap"), ("tools/recordings", "recording"),
                               ("tools/check", "check"), ("node", "replay")]:
            self.write(f"{folder}/include/rbsim/{header}.hpp", "#pragma once\n")
        self.write("sim_core/src/world.cpp", '#include "rbsim/core.hpp"\n' + function("step", 20))
        self.write("tools/recordings/src/recording.cpp",
                   '#include "rbsim/mcap.hpp"\n#include "rbsim/recording.hpp"\n'
                   "void read() { rbsim::mcap::IndexedReader reader; }\n")
        self.write("node/src/replay.cpp",
                   '#include "rbsim/recording.hpp"\n#include "rbsim/replay.hpp"\n'
                   "// not mcap::IndexedReader, which recordings wraps\n" + function("play", 100))

    def write(self, rel, text):
        path = self.root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")

    def run(self, script):
        p = subprocess.run([sys.executable, str(HERE / script), str(self.root)], capture_output=True, text=True)
        return p.returncode, p.stdout + p.stderr


class CheckerTest(unittest.TestCase):
    """A fresh tree per test, checked by the subclass's SCRIPT."""
    SCRIPT = None

    def setUp(self):
        self.tree = Tree()
        self.addCleanup(self.tree.tmp.cleanup)

    def assertFails(self, message):
        rc, out = self.tree.run(self.SCRIPT)
        self.assertEqual(rc, 1, out)
        self.assertIn(message, out)

    def assertPasses(self):
        rc, out = self.tree.run(self.SCRIPT)
        self.assertEqual(rc, 0, out)
        self.assertIn("0 problems", out)


class CheckModulesTest(CheckerTest):
    SCRIPT = "check_modules.py"

    def test_clean_tree_passes(self):
        self.assertPasses()

    def test_include_of_a_module_not_allowed_fails(self):
        self.tree.write("sim_core/src/bad.cpp", '#include "rbsim/recording.hpp"\n')
        self.assertFails("sim_core/src/bad.cpp: module core includes rbsim/recording.hpp of module recordings "
                         "(allowed: base)")

    def test_base_is_for_everyone_and_includes_nothing(self):
        self.tree.write("sim_core/base/include/rbsim/base.hpp", "#pragma once\n")
        self.tree.write("tools/mcap/src/use.cpp", '#include "rbsim/base.hpp"\n')
        self.assertEqual(self.tree.run("check_modules.py")[0], 0)
        self.tree.write("sim_core/base/src/bad.cpp", '#include "rbsim/core.hpp"\n')
        self.assertFails("sim_core/base/src/bad.cpp: module base includes rbsim/core.hpp of module core")

    def test_reader_outside_mcap_mcap_tools_and_recordings_fails(self):
        self.tree.write("tools/check/src/compare.cpp", "void f() { rbsim::mcap::StreamReader r; }\n")
        self.assertFails("tools/check/src/compare.cpp: module check uses the MCAP readers (mcap::StreamReader); "
                         "only mcap, mcap_tools, recordings may")

    def test_framing_outside_mcap_fails(self):
        self.tree.write("tools/recordings/src/sniff.cpp",
                        "const unsigned char kHead[] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\\r', '\\n'};\n")
        self.assertFails("tools/recordings/src/sniff.cpp: module recordings frames MCAP by hand (a copy of the magic)")
        self.tree.write("tools/recordings/src/sniff.cpp", "unsigned long n = le64(p + 1);\n")
        self.assertFails("(little-endian fields read by hand (le64))")

    def test_dds_header_outside_the_backends_fails(self):
        # The node's upper modules reach the network through the seam (node/middleware) alone.
        self.tree.write("node/dds/include/rbsim/dds.hpp", "#pragma once\n")
        self.tree.write("node/middleware/include/rbsim/middleware.hpp", "#pragma once\n")
        self.tree.write("node/bag/src/player.cpp", '#include "rbsim/middleware.hpp"\n')
        self.assertPasses()
        self.tree.write("node/bag/src/player.cpp", '#include "rbsim/dds.hpp"\n')
        self.assertFails("node/bag/src/player.cpp: module bag includes rbsim/dds.hpp of module dds")

    def test_cyclone_outside_dds_fails(self):
        self.tree.write("node/dds/src/dds.cpp", "#include <dds/dds.h>\nint p = dds_create_participant(0, 0, 0);\n")
        self.tree.write("node/bag/src/names.cpp", "// not dds_create_waitset(\n"
                        'std::string t = rbsim::msgs::dds_topic_name("/a"); const char* s = "dds_take(";\n')
        self.assertPasses()
        self.tree.write("node/bag/src/recorder.cpp", "#include <dds/dds.h>\n")
        self.assertFails("node/bag/src/recorder.cpp: module bag uses Cyclone DDS (#include <dds/dds.h>); only dds may")
        self.tree.write("node/bag/src/recorder.cpp", "void f(int w) { dds_waitset_wait(w, nullptr, 0, 0); }\n")
        self.assertFails("node/bag/src/recorder.cpp: module bag uses Cyclone DDS (dds_waitset_wait)")
        self.tree.write("node/bag/src/recorder.cpp", "struct ddsi_serdata* held;\n")
        self.assertFails("node/bag/src/recorder.cpp: module bag uses Cyclone DDS (ddsi_serdata)")

    def test_wall_clock_outside_base_fails(self):
        self.tree.write("sim_core/base/src/time.cpp", "long w() { timespec t; clock_gettime(CLOCK_REALTIME, &t); }\n")
        self.tree.write("node/bag/src/recorder.cpp", "// not system_clock::now() in a comment\n"
                        "auto t = rbsim::wall_ns(); auto m = std::chrono::steady_clock::now();\n")
        self.assertPasses()
        self.tree.write("node/bag/src/recorder.cpp", "auto t = std::chrono::system_clock::now();\n")
        self.assertFails("node/bag/src/recorder.cpp: module bag reads the wall clock itself (system_clock::now); "
                         "take rbsim::wall_ns")
        self.tree.write("node/bag/src/recorder.cpp", "void f(timespec* t) { clock_gettime(CLOCK_REALTIME, t); }\n")
        self.assertFails("module bag reads the wall clock itself (clock_gettime(CLOCK_REALTIME)")

    def test_type_name_outside_msgs_fails(self):
        self.tree.write("tools/msgs/include/rbsim/msgs.hpp",
                        'inline constexpr const char* kTrigger = "std_srvs/srv/Trigger";\n')
        self.tree.write("node/sim/src/services.cpp", '#include "rbsim_msgs/msg/Command.h"\n'
                        '// "rbsim_msgs/msg/Command" in a comment is no spelling\nconst char* t = kTrigger;\n')
        self.assertPasses()
        self.tree.write("node/sim/src/services.cpp", 'const char* t = "std_srvs/srv/Trigger";\n')
        self.assertFails("node/sim/src/services.cpp: module sim_node spells the type name std_srvs/srv/Trigger")

    def test_allowlist_ratchets(self):
        self.tree.write("tools/check/src/compare.cpp", "rbsim::mcap::IndexedReader r;\n")
        self.tree.write("test/architecture_allowlist.txt", "mcap-reader tools/check/src/compare.cpp\n")
        self.assertEqual(self.tree.run("check_modules.py")[0], 0)
        self.tree.write("tools/check/src/compare.cpp", "int r;  // mcap::IndexedReader gone\n")
        self.assertFails("mcap-reader tools/check/src/compare.cpp no longer breaks the rule: its entry can be removed")


class CheckSizesTest(CheckerTest):
    SCRIPT = "check_sizes.py"

    def test_clean_tree_passes(self):  # replay.cpp's play is 100 lines: at the limit
        self.assertPasses()

    def test_file_over_700_lines_fails(self):
        self.tree.write("tools/recordings/src/big.py", "x = 1\n" * 700)
        self.assertEqual(self.tree.run("check_sizes.py")[0], 0)
        self.tree.write("tools/recordings/src/big.py", "x = 1\n" * 701)
        self.assertFails("tools/recordings/src/big.py:1: file is 701 lines (limit 700)")

    def test_tests_are_exempt(self):
        self.tree.write("test/recordings/big_test.cpp", "int x;\n" * 900)
        self.tree.write("examples/demo/demo_test.cpp", "int x;\n" * 900)
        self.assertEqual(self.tree.run("check_sizes.py")[0], 0)

    def test_function_over_100_lines_fails(self):
        self.tree.write("node/src/replay.cpp", "namespace rbsim {\n\n" + function("play", 101) + "\n}  // namespace rbsim\n")
        self.assertFails("node/src/replay.cpp:3: function play is 101 lines (limit 100)")

    def test_sim_core_functions_are_measured(self):
        self.tree.write("sim_core/src/world.cpp", '#include "rbsim/core.hpp"\n' + function("step", 101))
        self.assertFails("sim_core/src/world.cpp:2: function step is 101 lines (limit 100)")

    def test_python_functions_are_measured(self):
        def py(lines):  # a method of exactly `lines` lines, its decorator the first
            return ("class World:\n    @property\n    def state(self):\n        n = 0\n" +
                    "        n += 1\n" * (lines - 4) + "        return n\n")
        self.tree.write("python/rbsim/world.py", py(100))
        self.assertPasses()
        self.tree.write("python/rbsim/world.py", py(101))
        self.assertFails("python/rbsim/world.py:2: function World.state is 101 lines (limit 100)")
        self.tree.write("tools/recordings/src/gen.py", "def main():\n" + "    pass\n" * 101)
        self.assertFails("tools/recordings/src/gen.py:1: function main is 102 lines (limit 100)")

    def test_member_functions_and_constructors_are_measured(self):
        body = "\n".join(["    ++n_;"] * 100)
        self.tree.write("tools/recordings/src/sink.hpp", textwrap.dedent("""\
            struct Sink {
             public:
              explicit Sink(int n) : n_{n}, f_([this] { return n_; }) {
            BODY
              }
              int n_{0};
            };
            """).replace("BODY", body))
        self.assertFails("tools/recordings/src/sink.hpp:3: function Sink is 102 lines (limit 100)")

    def test_allowlist_ratchets(self):
        self.tree.write("node/src/replay.cpp", function("play", 110))
        self.tree.write("test/architecture_allowlist.txt", "function 110 node/src/replay.cpp play\n")
        self.assertEqual(self.tree.run("check_sizes.py")[0], 0)
        self.tree.write("node/src/replay.cpp", function("play", 105))  # shrinking is fine
        self.assertEqual(self.tree.run("check_sizes.py")[0], 0)
        self.tree.write("node/src/replay.cpp", function("play", 111))
        self.assertFails("function play is 111 lines (limit 100; allow-listed at 110, which may only shrink)")
        self.tree.write("node/src/replay.cpp", function("play", 100))
        self.assertFails("function play of node/src/replay.cpp is 100 lines (limit 100): its entry can be removed")


if __name__ == "__main__":
    unittest.main()
