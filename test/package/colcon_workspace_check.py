#!/usr/bin/env python3
"""rbsim as a package of a ROS 2 workspace, checked after `colcon build` (scripts/test, release stage).

    colcon_workspace_check.py WORKSPACE --source ROOT

WORKSPACE is the folder colcon built in (src/rbsim -> ROOT, build/, install/ in colcon's default
isolated layout: install/rbsim/...). Checks, with no ROS 2 installed, what ROS 2's tools would
look up:
  - colcon read package.xml (colcon-ros): the run dependencies it recorded are package.xml's;
    package.xml is format 3, names rbsim at project(VERSION), and is installed as share/rbsim/package.xml;
  - `ros2 run rbsim rbsim`: lib/rbsim/rbsim is the installed rbsim, it runs (--help, --version, a
    10-step run writing steps 0..10 to CSV);
  - the ament index: packages/rbsim and packages/rbsim_msgs, rosidl_interfaces/rbsim_msgs listing
    exactly the definitions; share/rbsim_msgs holds them byte for byte, and a package.xml; none of
    the third-party definitions (ROS 2 has its own) is installed or indexed;
  - sourcing install/setup.sh in a clean shell puts bin/ on PATH (`rbsim` is the installed one)
    and the prefix on AMENT_PREFIX_PATH, where an index lookup then finds rbsim and rbsim_msgs.
Exits 1 with one line per failed check.
"""
import argparse
import csv
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

failures = []


def check(ok, msg):
    if not ok:
        failures.append(msg)
    return ok


def run(cmd, **kw):
    return subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=120, **kw)


def project_version(source):
    m = re.search(r"project\(rbsim VERSION ([0-9.]+)", (source / "CMakeLists.txt").read_text())
    return m.group(1)


def package_xml(path, name, version):
    """Checks a package.xml's format, name and version; returns its root element."""
    root = ET.parse(path).getroot()
    check(root.tag == "package" and root.get("format") == "3", f"{path}: not <package format=\"3\">")
    check(root.findtext("name") == name, f"{path}: name {root.findtext('name')!r}, expected {name!r}")
    check(root.findtext("version") == version,
          f"{path}: version {root.findtext('version')!r}, expected project(VERSION) {version!r}")
    check(root.findtext("export/build_type") == "cmake", f"{path}: build_type is not cmake")
    for tag in ["description", "maintainer", "license"]:
        check(root.find(tag) is not None, f"{path}: no <{tag}>")
    return root


def definitions(folder):
    """Interface files under a package folder, as rosidl lists them (msg/Name.msg, srv/Name.srv)."""
    return sorted(str(p.relative_to(folder)) for p in folder.glob("*/*") if p.suffix in (".msg", ".srv", ".action"))


def check_package(source, prefix, version):
    root = package_xml(source / "package.xml", "rbsim", version)
    installed = prefix / "share/rbsim/package.xml"
    if check(installed.is_file(), f"no {installed}"):
        check(installed.read_bytes() == (source / "package.xml").read_bytes(), f"{installed} differs from package.xml")
    # colcon-ros records the run dependencies it read from package.xml (colcon-core's package index).
    run_deps = {e.text for e in root if e.tag in ("depend", "exec_depend", "build_export_depend")}
    recorded = prefix / "share/colcon-core/packages/rbsim"
    if check(recorded.is_file(), f"no {recorded}: colcon did not install rbsim as a package"):
        got = set(filter(None, recorded.read_text().strip().split(":")))
        check(got == run_deps, f"colcon recorded run dependencies {sorted(got)}, package.xml has {sorted(run_deps)}:"
              " colcon did not read package.xml (colcon-ros)")


def check_executable(source, prefix, version, work):
    exe = prefix / "lib/rbsim/rbsim"
    if not check(exe.is_file() and os.access(exe, os.X_OK), f"no executable {exe} (ros2 run rbsim rbsim)"):
        return
    check(exe.resolve() == (prefix / "bin/rbsim").resolve(), f"{exe} is not the installed bin/rbsim")
    p = run([exe, "--help"])
    check(p.returncode == 0 and "Usage: rbsim" in p.stdout, f"{exe} --help exited {p.returncode}: {p.stderr.strip()}")
    p = run([exe, "--version"])
    check(p.stdout.strip() == f"rbsim {version}", f"{exe} --version printed {p.stdout.strip()!r}")
    out = work / "run.csv"
    p = run([exe, "run", source / "scenes/cantilever.xml", "--steps", "10", "--csv", out, "--quiet"])
    if not check(p.returncode == 0, f"{exe} run exited {p.returncode}: {p.stderr.strip()}"):
        return
    with out.open() as f:
        rows = list(csv.DictReader(f))
    steps = {}
    for r in rows:
        steps.setdefault(int(r["step"]), set()).add(r["body"])
    bodies = {len(b) for b in steps.values()}
    check(sorted(steps) == list(range(11)) and len(bodies) == 1 and min(bodies) > 0,
          f"{exe} run --steps 10 wrote steps {sorted(steps)} with body counts {sorted(bodies)}, "
          "expected steps 0..10 with every body")


def check_index(source, prefix):
    index = prefix / "share/ament_index/resource_index"
    for pkg in ["rbsim", "rbsim_msgs"]:
        marker = index / "packages" / pkg
        check(marker.is_file() and marker.stat().st_size == 0, f"no empty ament index marker {marker}")
    msgs_source = source / "tools/msgs/definitions/rbsim_msgs"
    want = definitions(msgs_source)
    listed = index / "rosidl_interfaces/rbsim_msgs"
    if check(listed.is_file(), f"no {listed}"):
        check(listed.read_text().splitlines() == want, f"{listed} lists {listed.read_text().split()}, expected {want}")
    msgs = prefix / "share/rbsim_msgs"
    got = definitions(msgs)
    check(got == want, f"{msgs} holds {got}, expected {want}")
    for rel in set(got) & set(want):
        check((msgs / rel).read_bytes() == (msgs_source / rel).read_bytes(), f"{msgs / rel} differs from its source")
    if check((msgs / "package.xml").is_file(), f"no {msgs}/package.xml"):
        root = ET.parse(msgs / "package.xml").getroot()
        check(root.findtext("name") == "rbsim_msgs", f"{msgs}/package.xml names {root.findtext('name')!r}")
    # The other definitions are ROS 2's own packages: installing them would shadow a sourced ROS 2's.
    for other in sorted(p.name for p in (source / "tools/msgs/definitions").iterdir() if p.is_dir()):
        if other == "rbsim_msgs":
            continue
        for path in [prefix / "share" / other, index / "packages" / other, index / "rosidl_interfaces" / other]:
            check(not path.exists(), f"{path} installed: {other} is ROS 2's own package")


def check_sourced(workspace, prefix):
    """A clean shell sourcing install/setup.sh, as a user does before `ros2 run`."""
    env = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp")}
    script = '. "$1/install/setup.sh" && printf "%s\\n" "$AMENT_PREFIX_PATH" && command -v rbsim'
    p = run(["sh", "-c", script, "sh", workspace], env=env)
    if not check(p.returncode == 0, f"sourcing {workspace}/install/setup.sh failed ({p.returncode}): {p.stderr.strip()}"):
        return
    lines = p.stdout.splitlines()
    ament_prefix_path = lines[0].split(":") if lines else []
    check(len(lines) == 2 and Path(lines[1]).resolve() == (prefix / "bin/rbsim").resolve(),
          f"after sourcing, rbsim on PATH is {lines[1:]}, expected {prefix / 'bin/rbsim'}")
    check(str(prefix) in ament_prefix_path, f"after sourcing, AMENT_PREFIX_PATH is {ament_prefix_path}, lacking {prefix}")
    # The ament index lookup of ros2 run and ros2 interface: the first prefix with the marker.
    for pkg, path in [("rbsim", "lib/rbsim/rbsim"), ("rbsim_msgs", "share/rbsim_msgs/msg/BodyStates.msg")]:
        found = next((Path(d) for d in ament_prefix_path
                      if (Path(d) / "share/ament_index/resource_index/packages" / pkg).is_file()), None)
        check(found is not None and (found / path).is_file(),
              f"an ament index lookup of {pkg} on AMENT_PREFIX_PATH {ament_prefix_path} finds no {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("workspace", type=Path)
    ap.add_argument("--source", type=Path, required=True)
    a = ap.parse_args()
    workspace, source = a.workspace.resolve(), a.source.resolve()
    prefix = workspace / "install/rbsim"
    if not prefix.is_dir():
        sys.exit(f"FAIL: no {prefix}: colcon did not install rbsim into {workspace}/install")
    version = project_version(source)
    with tempfile.TemporaryDirectory() as tmp:
        check_package(source, prefix, version)
        check_executable(source, prefix, version, Path(tmp))
        check_index(source, prefix)
        check_sourced(workspace, prefix)
    for f in failures:
        print("FAIL: " + f, file=sys.stderr)
    if failures:
        sys.exit(1)
    print(f"colcon workspace: rbsim {version} in {prefix}: lib/rbsim/rbsim runs, ament index and "
          f"{len(definitions(prefix / 'share/rbsim_msgs'))} rbsim_msgs definitions installed, found through install/setup.sh")


if __name__ == "__main__":
    main()
