#!/usr/bin/env python3
"""A stop at every stage of start-up: SIGINT and SIGTERM sent to `rbsim node`, `record`, `replay`,
`bridge` and `run --record` right after each line they print while starting, and at random delays
from their start (seeded; RBSIM_E2E_SEED repeats a run), many times. Every run must end as a stop
while running does: its exit status, its end line, and its outputs complete (a valid MCAP file
with CRCs checked by the official reader) or removed. The one other ending allowed is death by
the signal before the program could install its handlers (while the dynamic loader runs), and
only with nothing printed and no output on disk: nothing observable existed yet.

    startup_stops.py --index N --rbsim BUILD/rbsim --source-dir SRC --workdir DIR --venv BUILD/venv ...

Real processes over real DDS on loopback (the compiled-in loopback configuration), each case in
its own DDS domain and namespace, as in e2e.py (whose process and domain helpers it uses).
Exit status: 0 pass, 1 fail (every failed run listed).
"""

import argparse
import os
import random
import signal
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import e2e  # noqa: E402  (the process, domain and MCAP helpers of the end-to-end suite)
from e2e import Failure  # noqa: E402

SIGNALS = (signal.SIGINT, signal.SIGTERM)
RANDOM_RUNS = 4  # per command and signal, beside one run per start-up line
READY_TIMEOUT = 60.0  # a start-up line, on a loaded machine
EXIT_TIMEOUT = 60.0


class Command:
    """One command under test: how to start it, the lines it prints while starting (in order),
    and how a stop while running ends it."""

    def __init__(self, name, argv, startup, end_line, status, outputs=()):
        self.name, self.argv, self.startup, self.end_line = name, argv, startup, end_line
        self.status = status  # the exit status of a stop, given the signal and the run's stderr
        self.outputs = outputs  # files (MCAP) the command writes: complete or absent


def output_text(proc):
    return proc.stdout() + proc.stderr()


def wait_for_line(proc, text, timeout):
    """Until `text` is printed (polled every 5 ms: the signal goes out right after the line)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if text in output_text(proc):
            return
        if not proc.alive():
            raise Failure(f"{proc.name} exited before printing '{text}'\n{proc.output()}")
        time.sleep(0.005)
    raise Failure(f"{proc.name}: no '{text}' within {timeout} s\n{proc.output()}")


def check_ending(ctx, cmd, proc, sig, when, outputs):
    rc = proc.wait(EXIT_TIMEOUT)
    text = output_text(proc)
    what = f"{cmd.name} stopped by {signal.Signals(sig).name} {when}"
    if rc == -sig:
        # Killed by the default action: only before main() installed the handlers.
        leftovers = [o for o in outputs if os.path.exists(o)]
        ctx.check(text == "" and not leftovers,
                  f"{what}: killed by the signal after starting (printed {text!r}, left {leftovers})")
        return "killed before start"
    want = cmd.status(sig, text)
    ctx.check(rc == want, f"{what}: exit status {rc}, want {want}\n{proc.output()}")
    ctx.check(cmd.end_line in text, f"{what}: no end line '{cmd.end_line}'\n{proc.output()}")
    for o in outputs:
        if os.path.exists(o):
            try:
                e2e.Log(o)  # the official reader, CRCs validated
            except Exception as e:  # noqa: BLE001  (any reader error is the finding)
                ctx.check(False, f"{what}: {o} is not a complete MCAP file: {e}")
    return "clean"


def stop_runs(ctx, cmd, rng, counts):
    """One run per start-up line and signal, then RANDOM_RUNS at random delays per signal."""
    run = 0

    def start():
        nonlocal run
        run += 1
        outputs = [o.format(run=run) for o in cmd.outputs]
        argv = [a.format(run=run) if isinstance(a, str) else a for a in cmd.argv]
        return ctx.rb(f"{cmd.name}-{run}", *argv), outputs

    ready_after = 0.5
    for sig in SIGNALS:
        for k, line in enumerate(cmd.startup):
            proc, outputs = start()
            t0 = time.monotonic()
            wait_for_line(proc, line, READY_TIMEOUT)
            if k == len(cmd.startup) - 1:
                ready_after = max(ready_after, time.monotonic() - t0)
            proc.signal(sig)
            result = check_ending(ctx, cmd, proc, sig, f"after '{line}'", outputs)
            counts[result] = counts.get(result, 0) + 1
        for _ in range(RANDOM_RUNS):
            delay = rng.uniform(0.0, ready_after)
            proc, outputs = start()
            time.sleep(delay)
            proc.signal(sig)
            result = check_ending(ctx, cmd, proc, sig, f"{delay * 1e3:.0f} ms after its start", outputs)
            counts[result] = counts.get(result, 0) + 1


def commands(ctx, recording):
    scene = ctx.scene("cantilever.xml")
    fox = ("--foxglove", "127.0.0.1:0")
    listening = ("foxglove: listening on", "foxglove: open", "foxglove: layout")

    def zero(sig, text):
        return 0

    def record_status(sig, text):
        # A recorder that received nothing leaves nothing behind and says so (exit 1).
        return 1 if "nothing received" in text else 0

    return [
        Command("node", [*e2e.node_args(ctx, scene, "--rate", 1, "--loop", *fox, ns=ctx.ns + "_n{run}")],
                [*(f"rbsim node: {s}" for s in listening), "rbsim node: cantilever"],
                "rbsim node: stopped", zero),
        Command("record", [*e2e.record_args(ctx, ctx.path("rec-{run}.mcap"))],
                ["rbsim record: recording"], "messages received", record_status, [ctx.path("rec-{run}.mcap")]),
        Command("replay", ["replay", recording, "--domain", ctx.domain, "--namespace", ctx.ns + "_r{run}", "--loop",
                 *fox],
                [*(f"rbsim replay: {s}" for s in listening), "rbsim replay: " + recording],
                "rbsim replay: stopped", zero),
        Command("bridge", ["bridge", "--domain", ctx.domain, "--namespace", ctx.ns, *fox],
                [*(f"rbsim bridge: {s}" for s in listening), "rbsim bridge: relaying"],
                "rbsim bridge: stopped", zero),
        Command("run", ["run", scene, "--steps", 100000000, "--record", ctx.path("run-{run}.mcap")],
                [], "rbsim run: interrupted at step", lambda sig, text: 128 + sig, [ctx.path("run-{run}.mcap")]),
    ]


def case_startup_stops(ctx):
    seed = int(os.environ.get("RBSIM_E2E_SEED", str(ctx.pid)))
    ctx.log(f"seed {seed}")
    rng = random.Random(seed)
    recording = ctx.path("replayed.mcap")
    ctx.rbrun("record-run", "run", ctx.scene("cantilever.xml"), "--steps", 200, "--record", recording)
    # A node for the recorders and bridges to find (in ctx.ns; the nodes under test use their own).
    source = ctx.rb("source", *e2e.node_args(ctx, ctx.scene("cantilever.xml"), "--rate", 1, "--loop"))
    source.wait_for_text("rbsim node:", READY_TIMEOUT, stream="stderr")
    counts = {}
    for cmd in commands(ctx, recording):
        stop_runs(ctx, cmd, rng, counts)
    ctx.require(source.alive(), f"the source node stopped\n{source.output()}")
    source.signal(signal.SIGINT)
    e2e.exited_ok(ctx, source, EXIT_TIMEOUT, "the source node stopped with SIGINT")
    ctx.log(f"endings: {counts}")
    ctx.check(counts.get("clean", 0) > 0, "no run ended through its stop handlers")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    e2e.add_case_arguments(ap)
    args = ap.parse_args()
    args.case = "startup_stops"
    e2e.ensure_venv(args.venv, args.requirements)
    return e2e.run_case(args, case_startup_stops)


if __name__ == "__main__":
    sys.exit(main())
