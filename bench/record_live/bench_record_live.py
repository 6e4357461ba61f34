#!/usr/bin/env python3
"""Driver of scripts/bench-record-live (issue #14, item 3: recording keeps up in real time).

The real processes on 127.0.0.1 with rbsim's loopback Cyclone configuration, every wait bounded:
  1. `rbsim run SCENE --record run.mcap` (the 1,000-body grid, dt = 1 ms, default topics): CPU
     time per step, the baseline; its file also gives the messages every topic must have;
  2. `rbsim node SCENE --rate 1 --foxglove 127.0.0.1:0 --wait-for-subscribers 1`, one Foxglove
     client (bench/foxglove/live_client.js, its own process, subscribed to every channel before
     step 0), then `rbsim record live.mcap` (the subscriber the node waits for);
  3. CPU time of each process from wait4() (whole lifetime, every thread), sampled from /proc
     every second for the recorder's busiest window; steps and rate from the node's end line;
     the recorder's received/lost from its end line; the messages per topic in live.mcap from
     its summary with the official MCAP reader (the `mcap` package), against the node's published
     steps; with --check, `rbsim check live.mcap run.mcap --ignore-log-time` (every step of every
     topic present and identical to the offline run).
Prints each figure beside its target, met or MISSED; exits 1 when one is missed."""
import argparse
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

DT = 0.001
BODIES = 1000
TICK = os.sysconf("SC_CLK_TCK")
SETPRIV = next((p for p in ("/usr/bin/setpriv", "/bin/setpriv") if os.path.exists(p)), None)


class Failure(Exception):
    pass


class Proc:
    """A child process with stdout and stderr collected by threads; reaped with wait4() for its
    resource usage (CPU of all its threads); dies with this driver (setpriv --pdeathsig)."""

    def __init__(self, name, argv, env):
        self.name = name
        self.out, self.err = [], []
        self.code = None
        self.rusage = None
        self.started = time.monotonic()
        self.ended = None
        cmd = [SETPRIV, "--pdeathsig", "KILL", *argv] if SETPRIV else argv
        self.p = subprocess.Popen(cmd, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True, errors="replace")
        self.pid = self.p.pid  # setpriv execs: the same process
        self.threads = [threading.Thread(target=self._read, args=(s, b), daemon=True)
                        for s, b in ((self.p.stdout, self.out), (self.p.stderr, self.err))]
        for t in self.threads:
            t.start()

    @staticmethod
    def _read(stream, buf):
        for line in stream:
            buf.append(line)

    def text(self):
        return "".join(self.out) + "".join(self.err)

    def stderr(self):
        return "".join(self.err)

    def output(self):
        return f"--- {self.name} stdout ---\n{''.join(self.out)}--- {self.name} stderr ---\n{''.join(self.err)}"

    def alive(self):
        if self.code is None:
            self._reap(os.WNOHANG)
        return self.code is None

    def _reap(self, flags):
        pid, status, ru = os.wait4(self.pid, flags)
        if pid == 0:
            return
        self.ended = time.monotonic()
        self.code = os.waitstatus_to_exitcode(status)
        if self.code < 0:
            self.code = 128 - self.code
        self.rusage = ru
        self.p.returncode = self.code  # reaped here: Popen must not wait for it again
        for t in self.threads:
            t.join(timeout=10)

    def wait(self, timeout_s):
        """Exit status, or None if still running after timeout_s."""
        deadline = time.monotonic() + timeout_s
        while self.alive():
            if time.monotonic() > deadline:
                return None
            time.sleep(0.05)
        return self.code

    def stop(self, grace_s):
        """SIGINT (a clean stop for rbsim), then SIGKILL after grace_s."""
        if self.alive():
            os.kill(self.pid, signal.SIGINT)
        if self.wait(grace_s) is None:
            os.kill(self.pid, signal.SIGKILL)
            self.wait(30)

    def wait_for(self, pattern, timeout_s):
        deadline = time.monotonic() + timeout_s
        rx = re.compile(pattern)
        while True:
            m = rx.search(self.text())
            if m:
                return m
            if not self.alive() or time.monotonic() > deadline:
                state = "running" if self.code is None else f"exit {self.code}"
                raise Failure(f"{self.name}: no /{pattern}/ within {timeout_s} s ({state})\n{self.output()}")
            time.sleep(0.02)

    def cpu_s(self):
        return self.rusage.ru_utime + self.rusage.ru_stime if self.rusage else math.nan

    def wall_s(self):
        return (self.ended or time.monotonic()) - self.started


def proc_cpu_s(pid):
    """utime + stime of a running process (all threads) from /proc, or None once it is gone."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / TICK
    except (OSError, IndexError, ValueError):
        return None


class Sampler(threading.Thread):
    """Samples a process's CPU time every second (bounded by its life and by `stop`)."""

    def __init__(self, pid):
        super().__init__(daemon=True)
        self.pid = pid
        self.samples = []  # (monotonic s, cpu s)
        self.done = threading.Event()

    def run(self):
        while not self.done.is_set():
            cpu = proc_cpu_s(self.pid)
            if cpu is None:
                return
            self.samples.append((time.monotonic(), cpu))
            self.done.wait(1.0)

    def busiest(self, window_s):
        """The most cores used over any window of at least window_s between samples."""
        best, j = math.nan, 0
        s = self.samples
        for i in range(len(s)):
            while j < len(s) and s[j][0] - s[i][0] < window_s:
                j += 1
            if j == len(s):
                break
            cores = (s[j][1] - s[i][1]) / (s[j][0] - s[i][0])
            best = cores if math.isnan(best) else max(best, cores)
        return best


def mcap_counts(path):
    """{topic: messages} from the file's summary statistics, read with the official MCAP reader."""
    from mcap.reader import make_reader  # build/venv (scripts/setup)
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    if summary is None or summary.statistics is None:
        raise Failure(f"{path}: no summary statistics (not a finished MCAP file)")
    counts = {c.topic: 0 for c in summary.channels.values()}
    for cid, n in summary.statistics.channel_message_counts.items():
        counts[summary.channels[cid].topic] += n
    return counts


def verdict(ok):
    return "met" if ok else "MISSED"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rbsim", required=True)
    ap.add_argument("--root", required=True)
    ap.add_argument("--npm", required=True, help="scripts/setup's Node packages (build/npm)")
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated = wall seconds at --rate 1")
    ap.add_argument("--check", type=int, default=1, help="1: rbsim check live.mcap against run.mcap")
    ap.add_argument("--keep", default="", help="keep the work folder here (default: removed)")
    ap.add_argument("--security", action="store_true",
                    help="node and recorder secured (DDS Security, Enforce): a keystore made by rbsim security")
    a = ap.parse_args()
    seconds = a.seconds
    steps = math.ceil(round(seconds / DT, 9))
    # Bounds: the node may fall far behind real time on a loaded machine; it is stopped (and the
    # figures reported as missed) if it has not finished by then.
    node_bound_s = 10 * seconds + 120
    env = {k: v for k, v in os.environ.items()
           if k not in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_STATIC_PEERS", "ROS_LOCALHOST_ONLY")}
    env["CYCLONEDDS_URI"] = "file://" + os.path.join(a.root, "node", "config", "cyclonedds-loopback.xml")
    domain = str(100 + os.getpid() % 100)  # the benchmarks' domains (100..199)
    ns = f"bench_rl_{os.getpid()}"
    work = tempfile.mkdtemp(prefix="rbsim_bench_record_live_")
    procs = []
    results = []

    def report(label, ok, text):
        results.append(ok)
        print(f"  {label}: {text}: {verdict(ok)}", flush=True)

    try:
        # One binary for every process, even if the build is replaced while the benchmark runs.
        rbsim = os.path.join(work, "rbsim")
        shutil.copy2(a.rbsim, rbsim)
        if a.security:
            # The node's enclave is its name (/<ns>), the recorder's /rbsim_recorder, both allowed /<ns>'s topics.
            ks = os.path.join(work, "keystore")
            subprocess.run([rbsim, "security", "create-keystore", ks], check=True, capture_output=True, timeout=60)
            for enclave in ("/" + ns, "/rbsim_recorder"):
                subprocess.run([rbsim, "security", "create-enclave", ks, enclave, "--namespace", ns], check=True,
                               capture_output=True, timeout=60)
            env.update(ROS_SECURITY_ENABLE="true", ROS_SECURITY_STRATEGY="Enforce", ROS_SECURITY_KEYSTORE=ks)
        scene = os.path.join(work, f"grid{BODIES}.xml")
        with open(scene, "w") as f:
            subprocess.run([sys.executable, os.path.join(a.root, "bench", "make_grid_scene.py"), str(BODIES), str(DT),
                            repr(seconds)], stdout=f, check=True, timeout=60)
        print(f"bench-record-live: {BODIES} bodies, dt = {DT * 1000:g} ms, {steps} steps ({seconds:g} s), default topics, "
              f"domain {domain}, namespace /{ns}, loopback ({env['CYCLONEDDS_URI']}); {os.cpu_count()} cores, "
              f"load average {os.getloadavg()[0]:.2f} at the start; {a.rbsim} (built "
              f"{time.strftime('%Y-%m-%d %H:%M:%S', time.localtime(os.path.getmtime(a.rbsim)))})", flush=True)

        # 1. The baseline: rbsim run --record, same scene, steps, topics and namespace.
        run_mcap = os.path.join(work, "run.mcap")
        run = Proc("run", [rbsim, "run", scene, "--record", run_mcap, "--namespace", ns, "--progress", "never"], env)
        procs.append(run)
        if run.wait(node_bound_s) is None:
            run.stop(30)
            raise Failure(f"rbsim run --record did not finish within {node_bound_s:g} s")
        if run.code != 0:
            raise Failure(f"rbsim run --record failed (exit {run.code})\n{run.output()}")
        run_counts = mcap_counts(run_mcap)
        expected_total = sum(run_counts.values())
        per_step = {t: n for t, n in run_counts.items() if n > 1}
        latched = {t: n for t, n in run_counts.items() if n == 1}
        if any(n != steps + 1 for n in per_step.values()):
            raise Failure(f"run.mcap: per-step topics do not all have {steps + 1} messages: {per_step}")
        run_us = 1e6 * run.cpu_s() / steps
        print(f"  rbsim run --record: {steps} steps in {run.wall_s():.1f} s wall, {run.cpu_s():.2f} s CPU "
              f"({run_us:.0f} us per step), {os.path.getsize(run_mcap) / 1e6:.0f} MB, {expected_total} messages "
              f"({len(per_step)} per-step topics x {steps + 1}, {len(latched)} latched)", flush=True)

        # 2. The node with its Foxglove server; the client subscribes before the recorder starts, and
        #    the node steps once the recorder's reader matched.
        live_mcap = os.path.join(work, "live.mcap")
        node = Proc("node", [rbsim, "node", scene, "--rate", "1", "--domain", domain, "--namespace", ns,
                             "--foxglove", "127.0.0.1:0", "--wait-for-subscribers", "1"], env)
        procs.append(node)
        url = node.wait_for(r"foxglove: listening on (ws://127\.0\.0\.1:\d+)", 30).group(1)
        client = Proc("client", ["node", os.path.join(a.root, "bench", "foxglove", "live_client.js"), "--url", url,
                                 "--npm", a.npm, "--dt-ns", str(round(DT * 1e9)),
                                 "--timeout-s", str(round(node_bound_s + 120))], env)
        procs.append(client)
        client.wait_for(r"READY \d+", 60)
        rec = Proc("recorder", [rbsim, "record", live_mcap, "--domain", domain, "--namespace", ns,
                                "--max-messages", str(expected_total),
                                "--wall-duration", str(round(node_bound_s + 180))], env)
        procs.append(rec)
        rec_sampler = Sampler(rec.pid)
        rec_sampler.start()
        rec.wait_for(r"rbsim record: recording", 30)
        node_timed_out = node.wait(node_bound_s) is None
        if node_timed_out:
            node.stop(60)
        node_done = time.monotonic()
        # The recorder stops by itself after --max-messages; if messages are missing it never gets
        # there: a bounded wait, then a clean stop (SIGINT finishes the file).
        rec_timed_out = rec.wait(max(60.0, seconds)) is None
        if rec_timed_out:
            rec.stop(60)
        rec_sampler.done.set()
        client_timed_out = client.wait(60) is None
        if client_timed_out:
            client.stop(10)

        # 3. The figures.
        end = re.search(r"rbsim node: (done|stopped) after (\d+) steps in (.+?) \(([\d.e+]+) steps/s\), "
                        r"(\d+) messages published[^;\n]*(?:; (foxglove: .*))?", node.stderr())
        if node.code != 0 or not end:
            raise Failure(f"rbsim node failed (exit {node.code})\n{node.output()}")
        node_steps, node_rate, node_published = int(end.group(2)), float(end.group(4)), int(end.group(5))
        fox = end.group(6) or ""
        rec_end = re.search(r"rbsim record: (\d+) messages received, (\d+) lost", rec.stderr())
        if rec.code != 0 or not rec_end:
            raise Failure(f"rbsim record failed (exit {rec.code})\n{rec.output()}")
        rec_received, rec_lost = int(rec_end.group(1)), int(rec_end.group(2))
        live_counts = mcap_counts(live_mcap)
        published_steps = node_steps + 1  # step 0 is published too
        missing = {t: published_steps - live_counts.get(t, 0) for t in per_step}
        missing.update({t: 1 - min(1, live_counts.get(t, 0)) for t in latched})
        file_lost = sum(max(0, n) for n in missing.values())
        extra = {t: n for t, n in live_counts.items() if t not in run_counts}

        rtf = node_rate * DT
        print(f"  node: {end.group(0)} ({node.wall_s():.1f} s wall from its start)", flush=True)
        print(f"  recorder: {rec_end.group(0)} ({rec.wall_s():.1f} s wall, stopped "
              f"{'at --max-messages' if rec_received >= expected_total and not rec_timed_out else 'by SIGINT or --wall-duration'} "
              f"{rec.ended - node_done:.1f} s after the node ended)", flush=True)
        print(f"(item 3) recording keeps up in real time, {BODIES} bodies, dt = 1 ms, --rate 1, rbsim record + "
              f"1 Foxglove client, {seconds:g} s:", flush=True)
        report("steps published", node_steps == steps and not node_timed_out,
               f"{node_steps} of {steps}" + (" (node stopped: no end in time)" if node_timed_out else ""))
        # Real time is judged only when the machine can supply it: the node, the recorder and the
        # client together need `need` cores at 1,000 steps/s (their CPU over the simulated time).
        need = (node.cpu_s() + rec.cpu_s() + client.cpu_s()) / max(DT, node_steps * DT)
        cores = os.cpu_count() or 1
        if need < 0.9 * cores:
            report("real-time factor", rtf >= 0.95, f"{rtf:.3f} ({node_rate:.0f} steps/s for 1,000 due; the three "
                   f"processes need {need:.2f} of {cores} cores at real time; target >= 0.95)")
        else:
            print(f"  real-time factor: {rtf:.3f} ({node_rate:.0f} steps/s for 1,000 due): not judged, the node, "
                  f"recorder and client together need {need:.2f} cores at real time and this machine has {cores}",
                  flush=True)
        lost_detail = ", ".join(f"{t} {n}" for t, n in missing.items() if n) or "every step of every topic"
        report("lost", rec_lost == 0 and file_lost == 0 and not extra,
               f"recorder reports {rec_lost}, {rec_received} received of {node_published} published; live.mcap lacks "
               f"{file_lost} ({lost_detail}){f', unexpected topics {extra}' if extra else ''} (target 0)")
        # Cores the recorder needs to keep up in real time: its CPU time over the simulated time it
        # recorded (= the wall time at --rate 1 when the node keeps up; when it does not, the
        # recorder's mean over its wall time understates what real time would take).
        rec_cores = rec.cpu_s() / max(DT, node_steps * DT)
        report("recorder CPU", rec_cores < 1.0,
               f"{rec_cores:.2f} cores at real time ({rec.cpu_s():.1f} s CPU for {node_steps * DT:g} s simulated, "
               f"{1e6 * rec.cpu_s() / max(1, node_steps):.0f} us per step; measured mean "
               f"{rec.cpu_s() / rec.wall_s():.2f} cores over its {rec.wall_s():.1f} s wall, busiest 5 s "
               f"{rec_sampler.busiest(5.0):.2f}; target < 1)")
        node_us = 1e6 * node.cpu_s() / max(1, node_steps)
        ratio = node_us / run_us
        report("node CPU per published step", ratio <= 3.0,
               f"{node_us:.0f} us ({node.cpu_s():.1f} s CPU / {node_steps} steps) vs rbsim run --record "
               f"{run_us:.0f} us: {ratio:.2f}x (target <= 3x)")
        cl = None
        lines = [l for l in client.out if l.startswith("{")]
        if lines:
            cl = json.loads(lines[-1])
        dropped = re.search(r"(\d+) dropped", fox)
        dropped = int(dropped.group(1)) if dropped else -1
        if cl is None:
            report("Foxglove client", False, f"no result (exit {client.code})\n{client.output()}")
        else:
            short = {t: published_steps - cl["topics"].get(t, {}).get("count", 0) for t in per_step}
            short_n = sum(max(0, n) for n in short.values())
            report("Foxglove client", cl["gaps"] == 0 and short_n == 0 and dropped == 0,
                   f"{cl['messages']} messages ({cl['bytes'] / 1e6:.0f} MB), {cl['gaps']} gaps in per-step topics, "
                   f"{short_n} per-step messages short of {published_steps * len(per_step)}, server: {fox or '?'}; "
                   f"client CPU {client.cpu_s():.1f} s (target 0 gaps, 0 dropped)")
        if a.check:
            if node_steps != steps:
                report("rbsim check live.mcap run.mcap", False, "not run: the node did not publish every step")
            else:
                t0 = time.monotonic()
                chk = Proc("check", [rbsim, "check", live_mcap, run_mcap, "--ignore-log-time"], env)
                procs.append(chk)
                code = chk.wait(max(600.0, 20 * seconds))
                if code is None:
                    chk.stop(10)
                last = chk.text().strip().splitlines()[-1:] or ["(no output)"]
                report("rbsim check live.mcap run.mcap --ignore-log-time", code == 0,
                       f"exit {code}, {time.monotonic() - t0:.0f} s: {last[0]} (target: identical, every step)")
                if code != 0:
                    print(chk.output()[-4000:])
    except Failure as e:
        print(f"bench-record-live: {e}", flush=True)
        results.append(False)
    except subprocess.SubprocessError as e:
        print(f"bench-record-live: {e}", flush=True)
        results.append(False)
    finally:
        for p in procs:
            if p.code is None:
                p.stop(10)
        if a.keep:
            os.makedirs(a.keep, exist_ok=True)
            for f in os.listdir(work):
                shutil.move(os.path.join(work, f), os.path.join(a.keep, f))
        shutil.rmtree(work, ignore_errors=True)
    ok = bool(results) and all(results)
    print(f"bench-record-live: {'every target met' if ok else 'a target was MISSED'}", flush=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
