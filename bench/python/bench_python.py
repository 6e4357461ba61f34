#!/usr/bin/env python3
"""The Python package against its peers, in one run (issue 26, scripts/bench-python):

  step     world.step(1000) at 10,000 bodies (gravity, wind, springs) against World::step on the
           same world (BM_Step/wind_springs/10000 of rbsim_bench_world), rounds interleaved;
           target <= 1.05x.
  call     a Python loop of world.step() on a one-body scene: ns per call, beside a bare nanobind
           call that does nothing (rbsim._rbsim._noop) and beside World.step_index (a property).
  load     rbsim.Recording(...).body_states of a 1,000-body x 1,000-step recording against the
           official `mcap` + `mcap-ros2-support` readers decoding the same messages into the same
           arrays; aim >= 20x.

    bench_python.py --build BUILD [--rounds 5]
"""
import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def best_of(fn, repeat):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def bench_step(rbsim, bench, work, rounds):
    n, steps = 10_000, 1000
    scene = work / "wind_springs.xml"
    scene.write_text(subprocess.run([bench, "--scene", "wind_springs", str(n)], capture_output=True, text=True,
                                    check=True).stdout)
    world = rbsim.load_scene(scene).world()
    world.step(100)  # warm
    py, core = [], []
    for _ in range(rounds):
        py.append(best_of(lambda: world.step(steps), 3) / (steps * n) * 1e9)
        out = subprocess.run([bench, f"--benchmark_filter=^BM_Step/wind_springs/{n}$", "--benchmark_format=json",
                              "--benchmark_min_time=1"], capture_output=True, text=True, check=True).stdout
        b = json.loads(out)["benchmarks"][0]
        core.append(b["real_time"] * {"ns": 1, "us": 1e3, "ms": 1e6}[b["time_unit"]] / n)
    p, c = statistics.median(py), statistics.median(core)
    ok = p / c <= 1.05
    print(f"step   world.step(1000), N={n}: {p:.2f} ns/body-step; World::step {c:.2f}; "
          f"ratio {p / c:.3f}x (target <= 1.05: {'PASS' if ok else 'FAIL'})")
    return ok


def bench_call(rbsim, source):
    world = rbsim.load_scene(source / "test/data/fosssim/scenes/hollistictests/airplane.xml").world()
    noop = rbsim._rbsim._noop
    calls = 200_000

    def loop_step():
        for _ in range(calls):
            world.step()

    def loop_noop():
        for _ in range(calls):
            noop()

    def loop_prop():
        for _ in range(calls):
            world.step_index

    def loop_empty():
        for _ in range(calls):
            pass

    empty = best_of(loop_empty, 5)
    per = {name: (best_of(fn, 5) - empty) / calls * 1e9
           for name, fn in (("world.step()", loop_step), ("_noop()", loop_noop), ("world.step_index", loop_prop))}
    step_alone = best_of(lambda: world.step(calls), 5) / calls * 1e9
    print(f"call   per call, loop overhead removed: world.step() {per['world.step()']:.0f} ns "
          f"(of which the step itself {step_alone:.0f} ns, in one world.step({calls})); bare nanobind no-op "
          f"{per['_noop()']:.0f} ns; property {per['world.step_index']:.0f} ns")
    return True


def bench_load(rbsim, source, work, rounds):
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    bench_scene = work / "grid1000.xml"
    bench_scene.write_text(subprocess.run([sys.executable, source / "bench/make_grid_scene.py", "1000"],
                                          capture_output=True, text=True, check=True).stdout)
    rec = work / "grid1000.mcap"
    rbsim.run(bench_scene, steps=999, record=rec, topics=["body_states"], overwrite=True)

    def ours():
        t = rbsim.Recording(rec).body_states
        return t.x, t.vx

    def official():
        xs, vxs, steps = [], [], []
        with open(rec, "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            for _, _, message, decoded in reader.iter_decoded_messages(topics=["/rbsim/body_states"]):
                steps.append(decoded.step)
                xs.append([b.x for b in decoded.bodies])
                vxs.append([b.vx for b in decoded.bodies])
        return np.array(xs), np.array(vxs)

    a, b = ours(), official()
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]), "the two readers disagree"
    mine, theirs = [], []
    for _ in range(rounds):
        mine.append(best_of(ours, 3))
        theirs.append(best_of(official, 1))
    m, t = statistics.median(mine), statistics.median(theirs)
    print(f"load   1,000 bodies x 1,000 steps of body states: rbsim.Recording {m * 1e3:.1f} ms; official mcap + "
          f"mcap-ros2-support {t * 1e3:.0f} ms; {t / m:.1f}x faster (aim >= 20x: {'met' if t / m >= 20 else 'missed'})")
    return True


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", type=Path, required=True)
    ap.add_argument("--source", type=Path, default=Path(__file__).resolve().parents[2])
    ap.add_argument("--rounds", type=int, default=5)
    a = ap.parse_args()
    sys.path.insert(0, str(a.build / "python"))
    import rbsim
    with tempfile.TemporaryDirectory(prefix="rbsim-bench-python-") as tmp:
        work = Path(tmp)
        ok = bench_step(rbsim, a.build / "bench/rbsim_bench_world", work, a.rounds)
        bench_call(rbsim, a.source)
        bench_load(rbsim, a.source, work, a.rounds)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
