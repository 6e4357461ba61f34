#!/usr/bin/env python3
"""The module rules of docs/architecture.md, checked on the sources: each module includes only
the public headers of the modules its row allows (its own internals stay in its src/), and every
public header belongs to exactly one module.

    check_modules.py ROOT        # exit 1 listing every include that breaks a rule
"""
import pathlib
import re
import sys

# module: (folder, modules it may include). Mirrors docs/architecture.md's "Modules" table.
MODULES = {
    "core": ("sim_core", set()),
    "scene": ("sim_core/scene", {"core"}),
    "io": ("tools/io", {"core", "scene"}),
    "msgs": ("tools/msgs", {"core", "scene"}),
    "mcap": ("tools/mcap", set()),
    "mcap_tools": ("tools/mcap_tools", {"mcap", "core"}),
    "log": ("tools/log", {"io", "msgs", "mcap", "mcap_tools", "core", "scene"}),
    "check": ("tools/check", {"core", "scene", "io", "msgs", "mcap", "log"}),
    "golden": ("tools/golden", {"core", "scene", "io", "msgs", "mcap", "mcap_tools", "log"}),
    "render": ("tools/render", {"core", "scene", "io", "msgs", "mcap", "log"}),
    "node": ("node", {"core", "scene", "io", "msgs", "mcap", "mcap_tools", "log"}),
    "testing": ("tools/testing", {"core", "scene", "io", "msgs", "mcap", "log", "check", "golden"}),
    "foxglove": ("tools/foxglove", {"core", "scene", "io", "msgs"}),
    "cli": ("tools/cli", None),  # the executable: any module
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"rbsim/([A-Za-z0-9_]+\.hpp)"', re.M)


def module_of(root, path):
    """The module whose folder holds `path` (the longest matching folder)."""
    rel = path.relative_to(root).as_posix()
    best = None
    for name, (folder, _) in MODULES.items():
        if rel.startswith(folder + "/") and (best is None or len(folder) > len(MODULES[best][0])):
            best = name
    return best


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
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
    for name, (folder, allowed) in MODULES.items():
        if allowed is None:
            continue
        for path in sorted((root / folder).rglob("*")):
            if path.suffix not in (".cpp", ".hpp", ".h", ".in") or module_of(root, path) != name:
                continue
            for header in INCLUDE.findall(path.read_text(encoding="utf-8", errors="replace")):
                target = owner.get(header)
                if target is None and (path.parent / header).exists():
                    continue  # a private header beside it
                if target is None:
                    problems.append(f"{path.relative_to(root)}: includes rbsim/{header}, which no module exports")
                elif target != name and target not in allowed:
                    problems.append(f"{path.relative_to(root)}: module {name} includes rbsim/{header} of module "
                                    f"{target} (allowed: {', '.join(sorted(allowed)) or 'none'})")
    for p in problems:
        print(p)
    print(f"{len(owner)} public headers in {len(MODULES)} modules, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
