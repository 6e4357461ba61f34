#!/usr/bin/env python3
"""`rbsim log filter | merge | compress | cat --format csv` checked with the official Python `mcap`
reader (and writer, for the references of test/support/python/mcap_reference.py).

  merge:    two recordings of two nodes (rbsim run --record with different --namespace, different
            scenes and rates so their log times interleave) merged: the official reader finds the
            file in log-time order and every message of both inputs, equal times in input order,
            exactly what the reference merge writes.
  filter:   a window that starts mid-run: the same messages as the reference filter (latched
            topics from before the window included), `rbsim check` matches the reference file,
            and the slice renders on its own.
  compress: the same messages in log-time order under another codec and chunk size.
  cat csv:  one row per message with the official reader's log times and sequence numbers.

Started with any Python 3: it re-executes itself with the venv's interpreter (scripts/setup makes
it); a missing venv is a failure with instructions, never a skip.
"""

import argparse
import csv
import io
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support", "python"))
from rbsim_venv import ensure_venv  # noqa: E402

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


def run(cmd, expect=0):
    print("$ " + " ".join(cmd), flush=True)
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != expect:
        sys.stderr.write(p.stdout[-3000:] + p.stderr[-3000:])
        print(f"FAIL: {cmd[1:3]} exited with {p.returncode}, expected {expect}", file=sys.stderr)
        sys.exit(1)
    return p


def messages(path, log_time_order):
    """(topic, log_time, publish_time, sequence, data) of every message, as the official reader
    sees them (CRCs checked), in file order or log-time order."""
    from mcap.reader import make_reader
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        return [(c.topic, m.log_time, m.publish_time, m.sequence, bytes(m.data))
                for _, c, m in reader.iter_messages(log_time_order=log_time_order)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--venv", required=True)
    ap.add_argument("--requirements", required=True)
    ap.add_argument("--rbsim", required=True)
    ap.add_argument("--scenes", required=True, help="the repository's scenes/ folder")
    ap.add_argument("--workdir", required=True)
    args = ap.parse_args()
    ensure_venv(args.venv, args.requirements)
    import mcap_reference

    shutil.rmtree(args.workdir, ignore_errors=True)
    os.makedirs(args.workdir)
    at = lambda name: os.path.join(args.workdir, name)  # noqa: E731
    rbsim = args.rbsim
    a, b = at("node_a.mcap"), at("node_b.mcap")
    run([rbsim, "run", os.path.join(args.scenes, "cantilever.xml"), "-q", "--steps", "1200", "--namespace", "a",
         "--record", a])
    run([rbsim, "run", os.path.join(args.scenes, "chain.xml"), "-q", "--steps", "1500", "--namespace", "b",
         "--record-every", "3", "--record", b])

    # merge
    merged, ref = at("merged.mcap"), at("merged_ref.mcap")
    run([rbsim, "log", "merge", a, b, merged])
    run([rbsim, "log", "doctor", "--strict-message-order", merged])
    mcap_reference.merge_files([a, b], ref)
    got = messages(merged, log_time_order=False)
    times = [m[1] for m in got]
    check(all(x <= y for x, y in zip(times, times[1:])), "merge: the file is in log-time order")
    check(sorted(got) == sorted(messages(a, True) + messages(b, True)),
          f"merge: every message of both inputs, none more ({len(got)})")
    check(got == messages(ref, log_time_order=False),
          "merge: the reference merge's messages in its order (equal times: the first input's first)")
    shared = {m[1] for m in messages(a, True)} & {m[1] for m in messages(b, True)}
    check(len(shared) > 100, f"merge: the inputs share log times ({len(shared)}), so order at ties is tested")

    # filter: a window starting mid-run
    start, end = 0.4, 0.9
    sliced, ref = at("slice.mcap"), at("slice_ref.mcap")
    run([rbsim, "log", "filter", a, sliced, "--start", str(start), "--end", str(end)])
    run([rbsim, "log", "doctor", "--strict-message-order", sliced])
    mcap_reference.filter_file(a, ref, int(start * 1e9), int(end * 1e9))
    got = messages(sliced, log_time_order=False)
    check(got == messages(ref, log_time_order=False), f"filter: the reference filter's messages ({len(got)})")
    check(sum(1 for m in got if m[1] < start * 1e9) == 2, "filter: the scene and markers from before the window")
    run([rbsim, "check", sliced, ref])
    frames = at("frames")
    run([rbsim, "render", sliced, "--out", frames, "--fps", "10"])
    check(len(os.listdir(frames)) >= 5, f"filter: the slice renders on its own ({len(os.listdir(frames))} frames)")

    # compress
    packed = at("packed.mcap")
    run([rbsim, "log", "compress", b, packed, "--compression", "lz4", "--chunk-size", "200000"])
    run([rbsim, "log", "doctor", packed])
    check(messages(packed, False) == messages(b, True), "compress: the same messages in log-time order")

    # cat --format csv
    p = run([rbsim, "log", "cat", a, "--format", "csv", "--topics", "energy"])
    rows = list(csv.reader(io.StringIO(p.stdout)))
    want = [m for m in messages(a, True) if m[0] == "/a/energy"]
    check(rows[0][:3] == ["log_time", "publish_time", "sequence"] and len(rows[0]) > 3, "cat csv: header")
    check([(int(r[0]), int(r[1]), int(r[2])) for r in rows[1:]] == [(m[1], m[2], m[3]) for m in want],
          f"cat csv: one row per message ({len(rows) - 1})")
    check(all(len(r) == len(rows[0]) for r in rows), "cat csv: every row has every column")

    if failures:
        print(f"{len(failures)} checks failed", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
