#!/usr/bin/env python3
"""Throughput of `rbsim log filter` and `rbsim log merge` against the official Python `mcap`
writer doing the same job (test/support/python/mcap_reference.py) and against a plain copy of the
same bytes (read and written in 1 MiB blocks, fsynced as rbsim's AtomicFile fsyncs), on the same
recordings: two `rbsim run --record` of a generated grid scene under two namespaces.

Jobs (input bytes / wall seconds, median of --runs interleaved rounds):
  filter window   A -> the middle half of its log time, every topic
  filter topics   A -> every message but /tf and /clock
  merge           A + B -> one file
Outputs are zstd-compressed as the inputs are (--compression lz4 or none for the others' cost).
The plain copy of a job copies its input file(s) whole. Ratios printed: copy time / rbsim time
(target >= 0.5) and python time / rbsim time. Exit status 1 when a copy ratio misses its target."""

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "test", "support",
                                "python"))


def plain_copy(srcs, dst):
    with open(dst, "wb") as out:
        for src in srcs:
            with open(src, "rb") as f:
                while block := f.read(1 << 20):
                    out.write(block)
        out.flush()
        os.fsync(out.fileno())


def timed(job, out):
    if os.path.exists(out):
        os.remove(out)
    t0 = time.perf_counter()
    job()
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rbsim", required=True)
    ap.add_argument("--root", required=True, help="the repository")
    ap.add_argument("--tmp", default="/dev/shm")
    ap.add_argument("--bodies", type=int, default=300)
    ap.add_argument("--steps", type=int, default=1500)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--target", type=float, default=0.5, help="rbsim / plain copy throughput to reach")
    ap.add_argument("--compression", choices=("zstd", "lz4", "none"), default="zstd",
                    help="chunk compression of every job's output, rbsim's and Python's (inputs: zstd)")
    args = ap.parse_args()
    import mcap_reference

    work = os.path.join(args.tmp, f"rbsim_bench_log_tools_{os.getpid()}")
    os.makedirs(work)
    try:
        at = lambda name: os.path.join(work, name)  # noqa: E731
        scene = at("grid.xml")
        with open(scene, "w") as f:
            subprocess.run([sys.executable, os.path.join(args.root, "bench", "make_grid_scene.py"), str(args.bodies),
                            "0.001", str(args.steps / 1000)], stdout=f, check=True)
        a, b = at("a.mcap"), at("b.mcap")
        for path, ns in ((a, "a"), (b, "b")):
            subprocess.run([args.rbsim, "run", scene, "-q", "--steps", str(args.steps), "--namespace", ns,
                            "--record", path], check=True)
        size_a, size_b = os.path.getsize(a), os.path.getsize(b)
        start, end = 0.25 * args.steps / 1000, 0.75 * args.steps / 1000
        rb = lambda *cmd: (lambda: subprocess.run(  # noqa: E731
            [args.rbsim, "log", *cmd, "-q", "--compression", args.compression], check=True))
        z = args.compression
        out = at("out.mcap")
        jobs = [
            ("filter window", size_a, lambda: plain_copy([a], out),
             rb("filter", a, out, "--start", str(start), "--end", str(end)),
             lambda: mcap_reference.filter_file(a, out, int(start * 1e9), int(end * 1e9), compression=z)),
            ("filter topics", size_a, lambda: plain_copy([a], out),
             rb("filter", a, out, "--exclude-topics", "/tf,/clock"),
             lambda: mcap_reference.filter_file(a, out, topics=_topics_but(a, {"/tf", "/clock"}), compression=z)),
            ("merge", size_a + size_b, lambda: plain_copy([a, b], out), rb("merge", a, b, out),
             lambda: mcap_reference.merge_files([a, b], out, compression=z)),
        ]
        print(f"inputs: {size_a / 1e6:.1f} MB and {size_b / 1e6:.1f} MB ({args.bodies} bodies, {args.steps} steps, "
              f"zstd in, {args.compression} out), in {args.tmp}; median of {args.runs} rounds")
        print(f"{'job':<14} {'copy MB/s':>10} {'rbsim MB/s':>11} {'python MB/s':>12} {'rbsim/copy':>11} "
              f"{'rbsim/python':>13}")
        missed = 0
        for name, size, copy, rbsim, python in jobs:
            times = {"copy": [], "rbsim": [], "python": []}
            for _ in range(args.runs):
                for key, job in (("copy", copy), ("rbsim", rbsim), ("python", python)):
                    times[key].append(timed(job, out))
            t = {k: statistics.median(v) for k, v in times.items()}
            ratio_copy, ratio_python = t["copy"] / t["rbsim"], t["python"] / t["rbsim"]
            verdict = "PASS" if ratio_copy >= args.target else "FAIL"
            missed += verdict == "FAIL"
            print(f"{name:<14} {size / t['copy'] / 1e6:>10.0f} {size / t['rbsim'] / 1e6:>11.0f} "
                  f"{size / t['python'] / 1e6:>12.1f} {ratio_copy:>10.2f}x {ratio_python:>12.1f}x  "
                  f"{verdict} (target rbsim/copy >= {args.target}x)")
        return 1 if missed else 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _topics_but(path, left_out):
    from mcap.reader import make_reader
    with open(path, "rb") as f:
        return {c.topic for c in make_reader(f).get_summary().channels.values()} - left_out


if __name__ == "__main__":
    sys.exit(main())
