"""Running a test script inside the venv scripts/setup makes (official MCAP readers, Python
cyclonedds), shared by test/python/check_mcap.py and test/e2e/e2e.py."""

import os
import sys


def _fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def ensure_venv(venv, requirements):
    """Re-executes the calling script with the venv's Python unless it already runs there, then
    checks that the pinned versions in `requirements` are the ones installed. A missing or stale
    venv is a failure (exit 1) telling to run scripts/setup: these tests never skip for it."""
    venv = os.path.abspath(venv)
    python = os.path.join(venv, "bin", "python")
    if os.path.realpath(sys.prefix) != os.path.realpath(venv):
        if not os.path.exists(python):
            _fail(f"the Python venv is missing: {python} does not exist.\n"
                  f"Run scripts/setup to create it (for a build folder other than build/: "
                  f"BUILD_DIR={os.path.dirname(venv)} scripts/setup). This test never skips.")
        os.execv(python, [python, os.path.abspath(sys.argv[0])] + sys.argv[1:])
    from importlib import metadata

    wrong = []
    with open(requirements) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if "==" not in line:
                continue
            name, version = (s.strip() for s in line.split("==", 1))
            try:
                have = metadata.version(name)
            except metadata.PackageNotFoundError:
                have = None
            if have != version:
                wrong.append(f"{name}=={version} (installed: {have})")
    if wrong:
        _fail(f"the venv {venv} does not match {requirements}: {', '.join(wrong)}; run scripts/setup")
