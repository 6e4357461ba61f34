#!/usr/bin/env python3
"""The module rules of docs/architecture.md, checked on the sources: each module includes only
the public headers of the modules its row allows (its own internals stay in its src/), and every
public header belongs to exactly one module; only the modules of READER_MODULES use the MCAP
readers, no module but mcap frames MCAP by hand (magic, record prefix, opcodes), no module but msgs
spells a message or service type name ("std_srvs/srv/Trigger": msgs's constants instead), and no
module but dds includes a Cyclone DDS header or calls Cyclone's C API.

    check_modules.py ROOT [--allowlist FILE]   # exit 1 listing every break of a rule

The allow-list (default ROOT/test/architecture_allowlist.txt) names the files that still break
the reader or framing rule: a new one fails, and so does a listed one that no longer does.
"""
import argparse
import pathlib
import re
import sys

import check_common

# module: (folder, modules it may include). Mirrors docs/architecture.md's "Modules" table. A new
# module is one row; the modules of BASE are the lowest layer: every module may include them, and
# they include none of ours.
BASE = {"base"}
MODULES = {
    "base": ("sim_core/base", set()),
    "core": ("sim_core", set()),
    "scene": ("sim_core/scene", {"core"}),
    "run": ("tools/run", {"core", "scene"}),
    "control": ("tools/control", {"core", "scene", "run", "msgs", "recordings"}),
    "msgs": ("tools/msgs", {"core", "scene"}),
    "mcap": ("tools/mcap", set()),
    "mcap_tools": ("tools/mcap_tools", {"mcap"}),
    "recordings": ("tools/recordings", {"run", "msgs", "mcap", "mcap_tools", "core", "scene"}),
    "check": ("tools/check", {"core", "scene", "run", "msgs", "mcap", "recordings"}),
    "golden": ("tools/golden", {"core", "scene", "run", "msgs", "mcap", "mcap_tools", "recordings"}),
    "render": ("tools/render", {"core", "scene", "run", "msgs", "mcap", "recordings"}),
    "sros2": ("node/sros2", {"msgs"}),
    "middleware": ("node/middleware", {"core", "msgs"}),
    "dds": ("node/dds", {"middleware", "sros2", "core", "msgs"}),
    "memory": ("node/memory", {"middleware", "core", "msgs"}),
    "sim_node": ("node/sim", {"middleware", "core", "scene", "run", "control", "msgs"}),
    "bag": ("node/bag", {"middleware", "core", "scene", "run", "control", "msgs", "mcap", "mcap_tools", "recordings"}),
    "bridge": ("node/bridge", {"middleware", "core", "scene", "run", "control", "msgs"}),
    "testing": ("tools/testing", {"core", "scene", "run", "msgs", "mcap", "recordings", "check", "golden", "control"}),
    "foxglove": ("tools/foxglove", {"core", "scene", "run", "control", "msgs"}),
    "python": ("python", {"core", "scene", "run", "control", "msgs", "mcap", "recordings", "check"}),
    "cli": ("tools/cli", None),  # the executable: any module
}
# Cyclone DDS lives in node/dds alone (the seam's backend on the network, as rmw_cyclonedds_cpp is
# under rcl; sim_node, bag and bridge reach it only through node/middleware's handles, and the rows
# above keep rbsim/dds.hpp and dds's other headers out of them): no other module includes its
# headers or uses its C API (dds_*
# calls, dds_*_t / ddsi_* / ddsrt_* types, DDS_* constants). msgs's own dds_topic_name and
# dds_type_name (the ROS 2 naming rule, no Cyclone) are not Cyclone's.
CYCLONE_MODULES = {"dds"}
CYCLONE_INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]((?:dds|ddsc|ddsi|ddsrt)/[^>"]*)', re.M)
CYCLONE_API = re.compile(r"(?<![\w:.>])(dds_(?!topic_name\b|type_name\b)\w+\s*\(|dds_\w+_t\b|ddsi_\w+|ddsrt_\w+|"
                         r"DDS_[A-Z][A-Z0-9_]*\b)")
INCLUDE = re.compile(r'^\s*#\s*include\s+"rbsim/([A-Za-z0-9_]+\.hpp)"', re.M)
SOURCE_SUFFIXES = (".cpp", ".hpp", ".h", ".in")

# The reading side of rbsim/mcap.hpp (the Writer and the record types are for everyone): other
# modules read recordings through the recordings module (rbsim/recording.hpp) or an mcap_tools tool.
READER_MODULES = {"mcap", "mcap_tools", "recordings"}
READER_API = re.compile(r"\bmcap\s*::\s*(StreamReader|IndexedReader|StreamOptions|IndexedOptions|"
                        r"ReadMessagesOptions|MessageEntry|RecordEntry|parse_record|decompress_chunk)\b")
# MCAP's framing by hand: the magic, the record prefix <opcode u8><length u64>, opcodes.
FRAMING_MODULES = {"mcap"}
FRAMING = [
    (re.compile(r"\bkMagic\b"), "the magic (kMagic)"),
    (re.compile(r"0x89\s*,\s*'M'\s*,\s*'C'\s*,\s*'A'\s*,\s*'P'|\\x89MCAP"), "a copy of the magic"),
    (re.compile(r"\bk(?:Record)?Prefix\b"), "the record prefix (kPrefix)"),
    (re.compile(r"\b(?:read_|load_)?le(?:16|32|64)\s*\("), "little-endian fields read by hand (le64)"),
    (re.compile(r"\bmcap\s*::\s*Opcode\b"), "record opcodes (mcap::Opcode)"),
]


def allowed_includes(name):
    """The modules `name` may include (None: any)."""
    allowed = MODULES[name][1]
    return None if allowed is None else allowed | (BASE - {name})


def module_of(root, path):
    """The module whose folder holds `path` (the longest matching folder)."""
    rel = path.relative_to(root).as_posix()
    best = None
    for name, (folder, _) in MODULES.items():
        if rel.startswith(folder + "/") and (best is None or len(folder) > len(MODULES[best][0])):
            best = name
    return best


def check_includes(root, name, path, text, owner, problems):
    allowed = allowed_includes(name)
    if allowed is None:
        return
    for header in INCLUDE.findall(text):
        target = owner.get(header)
        if target is None and (path.parent / header).exists():
            continue  # a private header beside it
        if target is None:
            problems.append(f"{path.relative_to(root)}: includes rbsim/{header}, which no module exports")
        elif target != name and target not in allowed:
            problems.append(f"{path.relative_to(root)}: module {name} includes rbsim/{header} of module "
                            f"{target} (allowed: {', '.join(sorted(allowed)) or 'none'})")
# A ROS type name spelt in a string literal: msgs holds them (topics(), interfaces.hpp's kType and
# kService); every other module takes its constants, so a type is renamed in one place.
TYPE_NAME_MODULES = {"msgs"}
TYPE_NAME = re.compile(r'"([a-z][a-z0-9_]*/(?:msg|srv|action)/[A-Z][A-Za-z0-9_]*)"')


def type_name_use(name, text):
    """The first message or service type name `text` spells, if module `name` may not."""
    if name in TYPE_NAME_MODULES:
        return None
    m = TYPE_NAME.search(check_common.strip(text, literals=False))
    return m and m.group(1)


def reader_use(name, text):
    """The first MCAP reader name `text` uses, if module `name` may not."""
    if name in READER_MODULES:
        return None
    m = READER_API.search(check_common.strip(text))
    return m and f"mcap::{m.group(1)}"


def framing_use(name, text):
    """What of MCAP's framing `text` spells out, if module `name` may not."""
    if name in FRAMING_MODULES:
        return None
    code = check_common.strip(text, literals=False, directives=False)
    return next((what for pattern, what in FRAMING if pattern.search(code)), None)


def cyclone_use(name, text):
    """The first Cyclone DDS header or API name `text` uses, if module `name` may not."""
    if name in CYCLONE_MODULES:
        return None
    m = CYCLONE_INCLUDE.search(text)
    if m:
        return f"#include <{m.group(1)}>"
    m = CYCLONE_API.search(check_common.strip(text))
    return m and m.group(1).rstrip("( \t")


# The clocks: base's time.hpp reads them (monotonic_ns paces and times out, wall_ns stamps); a
# module reading the system clock itself is a second rule for how wall time becomes nanoseconds.
CLOCK_MODULES = {"base"}
SYSTEM_CLOCK = re.compile(r"\bsystem_clock\s*::\s*now\b|\bclock_gettime\s*\(\s*CLOCK_REALTIME\b")


def clock_use(name, text):
    """The system clock reading `text` makes, if module `name` may not."""
    if name in CLOCK_MODULES:
        return None
    m = SYSTEM_CLOCK.search(check_common.strip(text))
    return m and m.group(0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("root", type=pathlib.Path)
    ap.add_argument("--allowlist", type=pathlib.Path, help="default: ROOT/test/architecture_allowlist.txt")
    a = ap.parse_args()
    root = a.root.resolve()
    allowlist = a.allowlist or root / "test" / "architecture_allowlist.txt"
    listed = check_common.read_allowlist(allowlist)
    owner, problems = {}, []
    for name, (folder, _) in MODULES.items():
        for header in (root / folder / "include" / "rbsim").glob("*.hpp"):
            if module_of(root, header) != name:
                continue
            if header.name in owner:
                problems.append(f"rbsim/{header.name} is public in both {owner[header.name]} and {name}")
            owner[header.name] = name
    if not owner:
        problems.append("no public headers found: wrong ROOT?")
    readers, framers = set(), set()
    for name, (folder, _) in MODULES.items():
        for path in sorted((root / folder).rglob("*")):
            if path.suffix not in SOURCE_SUFFIXES or module_of(root, path) != name:
                continue
            text = path.read_text(encoding="utf-8", errors="replace")
            rel = path.relative_to(root).as_posix()
            check_includes(root, name, path, text, owner, problems)
            used = reader_use(name, text)
            if used:
                readers.add(rel)
                if rel not in listed["mcap-reader"]:
                    problems.append(f"{rel}: module {name} uses the MCAP readers ({used}); only "
                                    f"{', '.join(sorted(READER_MODULES))} may")
            cyclone = cyclone_use(name, text)
            if cyclone:
                problems.append(f"{rel}: module {name} uses Cyclone DDS ({cyclone}); only "
                                f"{', '.join(sorted(CYCLONE_MODULES))} may (node/dds, behind the middleware seam)")
            spelt = type_name_use(name, text)
            if spelt:
                problems.append(f"{rel}: module {name} spells the type name {spelt}; take msgs's constant")
            clock = clock_use(name, text)
            if clock:
                problems.append(f"{rel}: module {name} reads the wall clock itself ({clock}); "
                                "take rbsim::wall_ns (rbsim/time.hpp)")
            framed = framing_use(name, text)
            if framed:
                framers.add(rel)
                if rel not in listed["mcap-framing"]:
                    problems.append(f"{rel}: module {name} frames MCAP by hand ({framed}); only tools/mcap may")
    for kind, found in (("mcap-reader", readers), ("mcap-framing", framers)):
        for rel in sorted(set(listed[kind]) - found):
            problems.append(f"{allowlist}: {kind} {rel} no longer breaks the rule: its entry can be removed")
    for p in problems:
        print(p)
    print(f"{len(owner)} public headers in {len(MODULES)} modules, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
