#!/usr/bin/env python3
"""End-to-end tests of the DDS side: the real `rbsim node`, `rbsim record` and `rbsim replay` as
separate processes talking real DDS on loopback (or, in the netns case, across a veth pair
between two network namespaces the test creates).

    e2e.py --case NAME --index N --rbsim BUILD/rbsim --source-dir SRC --workdir DIR --venv BUILD/venv ...

Every case uses its own DDS domain id (one of 200..232 no other running case holds: a flock
registry in the temp directory) and its own ROS namespace (e2e_<case>_<pid>), so parallel runs,
also from other build trees, do not cross. rbsim
processes run with CYCLONEDDS_URI and ROS 2's ROS_DOMAIN_ID, ROS_AUTOMATIC_DISCOVERY_RANGE,
ROS_STATIC_PEERS and ROS_LOCALHOST_ONLY removed (the compiled-in loopback configuration) unless a case
sets it to node/config/cyclonedds-loopback.xml or, in the netns case, to a configuration bound to
the veth addresses inside the namespaces. Every wait is bounded in time; every process started
is killed at the end (and, through PR_SET_PDEATHSIG, if this driver dies); namespaces are
deleted in a finally block and stale ones of dead runs are swept at the start.

Exit status: 0 pass, 1 fail (every failed check listed), 77 skip (netns not permitted).
Started with any Python 3: it re-executes itself with the venv's interpreter (scripts/setup makes
it); a missing venv is a failure with instructions, never a skip.
"""

import argparse
import ctypes
import json
import math
import os
import random
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import time
import traceback

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support", "python"))
from rbsim_venv import ensure_venv  # noqa: E402  (test/support/python: into the venv scripts/setup makes)

SKIP = 77


# ---------------------------------------------------------------------------------------------
# Processes


class Failure(Exception):
    pass


_libc = ctypes.CDLL(None, use_errno=True)
PR_SET_PDEATHSIG = 1


def _child_setup(fsize_limit=None):
    def setup():
        # Die with the driver (ctest kills the driver on a timeout): no orphaned DDS processes.
        _libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if fsize_limit is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (fsize_limit, fsize_limit))
    return setup


class Proc:
    def __init__(self, ctx, name, argv, env, fsize_limit=None):
        self.ctx, self.name, self.argv = ctx, name, argv
        self.out_path = os.path.join(ctx.workdir, f"{name}.out")
        self.err_path = os.path.join(ctx.workdir, f"{name}.err")
        self._out = open(self.out_path, "w")
        self._err = open(self.err_path, "w")
        self.started = time.monotonic()
        ctx.log(f"start {name}: {' '.join(argv)}")
        # restore_signals (default): SIGPIPE/SIGXFSZ back to SIG_DFL in the child, as from a shell.
        self.p = subprocess.Popen(argv, env=env, stdin=subprocess.DEVNULL, stdout=self._out, stderr=self._err,
                                  preexec_fn=_child_setup(fsize_limit))
        self.rc = None

    def alive(self):
        return self.p.poll() is None

    def signal(self, sig):
        if self.alive():
            self.ctx.log(f"{signal.Signals(sig).name} -> {self.name}")
            self.p.send_signal(sig)

    def wait(self, timeout):
        try:
            self.rc = self.p.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.kill()
            raise Failure(f"{self.name} did not exit within {timeout} s\n{self.output()}")
        self._out.close()
        self._err.close()
        self.ctx.log(f"{self.name} exited with {self.rc} after {time.monotonic() - self.started:.2f} s")
        return self.rc

    def kill(self):
        if self.alive():
            self.p.kill()
        try:
            self.p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            pass

    def stdout(self):
        with open(self.out_path, errors="replace") as f:
            return f.read()

    def stderr(self):
        with open(self.err_path, errors="replace") as f:
            return f.read()

    def output(self):
        return f"--- {self.name} stdout ---\n{self.stdout()}--- {self.name} stderr ---\n{self.stderr()}"

    def wait_for_text(self, text, timeout, stream="stdout"):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if text in (self.stdout() if stream == "stdout" else self.stderr()):
                return
            if not self.alive():
                break
            time.sleep(0.05)
        raise Failure(f"{self.name}: no '{text}' on {stream} within {timeout} s\n{self.output()}")


DOMAINS = range(200, 233)  # clear of ROS's default 0, rbsim's benchmarks (100..199) and test/dds (142)


def claim_domain(index, pid):
    """A DDS domain id no other e2e case on this machine uses right now (any build tree): an
    exclusive flock on <tmp>/rbsim-e2e-domains/<id>, held until this process exits (the kernel
    drops it even on SIGKILL). Distinct domains keep /clock, which every node publishes outside
    any namespace, from crossing between cases that run at the same time."""
    import fcntl
    import tempfile

    lock_dir = os.path.join(tempfile.gettempdir(), "rbsim-e2e-domains")
    os.makedirs(lock_dir, exist_ok=True)
    first = (index * 5 + pid) % len(DOMAINS)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        for k in range(len(DOMAINS)):
            domain = DOMAINS[(first + k) % len(DOMAINS)]
            fd = os.open(os.path.join(lock_dir, str(domain)), os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return domain, fd
            except OSError:
                os.close(fd)
        time.sleep(0.2)
    raise SystemExit(f"FAIL: no free DDS domain in {DOMAINS.start}..{DOMAINS.stop - 1} within 30 s ({lock_dir})")


class Ctx:
    def __init__(self, args):
        self.args = args
        self.rbsim = os.path.abspath(args.rbsim)
        self.src = os.path.abspath(args.source_dir)
        self.workdir = os.path.abspath(args.workdir)
        self.index = args.index
        self.pid = os.getpid()
        self.domain, self._domain_lock = claim_domain(args.index, self.pid)
        self.ns = f"e2e_{args.case}_{self.pid}"
        self.procs = []
        self.failures = []
        self.notes = []
        self.t0 = time.monotonic()
        self.loopback_xml = os.path.join(self.src, "node", "config", "cyclonedds-loopback.xml")
        shutil.rmtree(self.workdir, ignore_errors=True)
        os.makedirs(self.workdir)
        self.log(f"case {args.case}: domain {self.domain}, namespace /{self.ns}, workdir {self.workdir}")

    def log(self, msg):
        print(f"[{time.monotonic() - self.t0:7.2f}] {msg}", flush=True)

    def env(self, uri=None):
        env = dict(os.environ)
        env.pop("CYCLONEDDS_URI", None)  # the compiled-in loopback configuration
        # rbsim honours ROS 2's variables: none of a developer's settings (SUBNET...) gets in.
        for name in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_STATIC_PEERS", "ROS_LOCALHOST_ONLY",
                     "ROS_SECURITY_ENABLE", "ROS_SECURITY_STRATEGY", "ROS_SECURITY_KEYSTORE",
                     "ROS_SECURITY_ENCLAVE_OVERRIDE"):
            env.pop(name, None)
        if uri:
            env["CYCLONEDDS_URI"] = uri
        return env

    def path(self, name):
        return os.path.join(self.workdir, name)

    def scene(self, name):
        return os.path.join(self.src, "scenes", name)

    def start(self, name, argv, env=None, fsize_limit=None):
        p = Proc(self, name, argv, env if env is not None else self.env(), fsize_limit)
        self.procs.append(p)
        return p

    def rb(self, name, *args, env=None, fsize_limit=None):
        return self.start(name, [self.rbsim, *map(str, args)], env=env, fsize_limit=fsize_limit)

    def run(self, name, argv, timeout=120, env=None):
        """Runs a command to completion (bounded); returns (rc, stdout, stderr)."""
        p = self.start(name, argv, env=env)
        rc = p.wait(timeout)
        return rc, p.stdout(), p.stderr()

    def rbrun(self, name, *args, timeout=120, env=None, ok=True):
        rc, out, err = self.run(name, [self.rbsim, *map(str, args)], timeout=timeout, env=env)
        if ok and rc != 0:
            raise Failure(f"rbsim {' '.join(map(str, args))} exited with {rc}\n{out}{err}")
        return rc, out, err

    def check(self, cond, what):
        if cond:
            return True
        self.failures.append(what)
        self.log(f"FAIL: {what}")
        return False

    def require(self, cond, what):
        if not cond:
            raise Failure(what)

    def note(self, msg):
        self.notes.append(msg)
        self.log(f"NOTE: {msg}")

    def cleanup(self):
        for p in self.procs:
            if p.alive():
                self.log(f"cleanup: killing {p.name}")
                p.kill()


def exited_ok(ctx, proc, timeout, what=None):
    rc = proc.wait(timeout)
    ctx.check(rc == 0, f"{what or proc.name} exited with {rc} (want 0)\n{proc.output()}")
    return rc


# ---------------------------------------------------------------------------------------------
# MCAP and CDR


class Log:
    """A recording read with the official Python reader (CRCs validated), in log-time order."""

    def __init__(self, path):
        from mcap.reader import make_reader

        self.path = path
        self.messages = []  # (topic, schema name, log_time, publish_time, sequence, payload)
        with open(path, "rb") as f:
            reader = make_reader(f, validate_crcs=True)
            self.summary = reader.get_summary()
            for schema, channel, m in reader.iter_messages(log_time_order=True):
                self.messages.append((channel.topic, schema.name if schema else "", m.log_time, m.publish_time,
                                      m.sequence, bytes(m.data)))

    def topics(self):
        return sorted({m[0] for m in self.messages})

    def by_topic(self):
        out = {}
        for m in self.messages:
            out.setdefault(m[0], []).append(m)
        return out

    def payloads(self, topic):
        return [m[5] for m in self.messages if m[0] == topic]

    def offered(self, suffix):
        """(history, depth) of the offered_qos_profiles metadata of the topic ending in `suffix`."""
        for ch in self.summary.channels.values():
            if ch.topic.rsplit("/", 1)[-1] == suffix:
                text = ch.metadata.get("offered_qos_profiles", "")
                fields = dict(line.strip("- ").split(": ", 1) for line in text.split("\n") if ": " in line)
                return fields.get("history"), fields.get("depth")
        return None

    def by_suffix(self):
        """payloads per topic name without its namespace ("body_states", "clock")."""
        out = {}
        for m in self.messages:
            out.setdefault(m[0].rsplit("/", 1)[-1], []).append(m[5])
        return out


def read_stream_messages(path):
    """(topic, log_time, publish_time, sequence, payload) of every message in the complete
    chunks of a possibly truncated file, read with the official streaming reader (CRCs checked)."""
    from mcap.stream_reader import StreamReader
    from mcap.records import Channel, Message

    channels, out = {}, []
    with open(path, "rb") as f:
        try:
            for record in StreamReader(f, skip_magic=False, validate_crcs=True).records:
                if isinstance(record, Channel):
                    channels[record.id] = record.topic
                elif isinstance(record, Message):
                    out.append((channels.get(record.channel_id, "?"), record.log_time, record.publish_time,
                                record.sequence, bytes(record.data)))
        except Exception:  # the truncated tail
            pass
    return out


def wait_recorded(ctx, proc, path, enough, timeout, what):
    """Waits (bounded: `timeout` s, polled every 0.1 s) until the complete chunks of the recording
    `path`, which `proc` (rbsim record, best with a small --chunk-size) is still writing, satisfy
    `enough(messages)` (read_stream_messages' tuples); fails naming `what` otherwise."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if os.path.exists(path) and enough(read_stream_messages(path)):
            return
        if not proc.alive():
            break
        time.sleep(0.1)
    raise Failure(f"{proc.name}: {what} not in {path} within {timeout} s\n{proc.output()}")


def per_topic(messages):
    """How many messages of read_stream_messages() per topic name without its namespace."""
    out = {}
    for m in messages:
        suffix = m[0].rsplit("/", 1)[-1]
        out[suffix] = out.get(suffix, 0) + 1
    return out


def recorded_span(got, suffix="body_states"):
    """Seconds of log time between the first and the last message of a topic in read_stream_messages()."""
    t = [m[1] for m in got if m[0].rsplit("/", 1)[-1] == suffix]
    return (max(t) - min(t)) * 1e-9 if len(t) > 1 else 0.0


def first_published(log):
    """Topic of the message published first (publish_time: the sample's source timestamp). The
    order in which a subscriber receives messages of different writers is not defined by DDS."""
    return min(log.messages, key=lambda m: m[3])[0] if log.messages else None


def cdr_header_end(cdr):
    """Offset (after the 4-byte encapsulation) just past std_msgs/Header: stamp, frame_id."""
    (length,) = struct.unpack_from("<I", cdr, 4 + 8)
    return 8 + 4 + length  # relative to the end of the encapsulation header


def stamp_of(cdr):
    return struct.unpack_from("<iI", cdr, 4)


# What a node publishes by default: the latched scene description and markers, once per run, and
# six per-step topics.
LATCHED = ("scene", "markers")
PER_STEP = ("body_states", "spring_states", "energy", "tf", "springs", "clock")


def sim_stamp(suffix, cdr):
    """The simulated time of a per-step message: its header stamp (the clock for /clock; the
    first marker's or transform's, after the sequence length, for markers and /tf)."""
    return struct.unpack_from("<iI", cdr, 8 if suffix in ("markers", "tf") else 4)


def step_of(cdr):
    """The step field of rbsim BodyStates / SpringStates / EnergyTerms (after the header)."""
    off = cdr_header_end(cdr)
    off += (-off) % 8
    return struct.unpack_from("<Q", cdr, 4 + off)[0]


def expect_indexed(ctx, log, count=None):
    s = log.summary
    if not ctx.check(s is not None and s.statistics is not None and len(s.chunk_indexes) > 0,
                     f"{log.path}: not a finished, indexed MCAP file (no summary / chunk indexes)"):
        return
    ctx.check(s.statistics.message_count == len(log.messages),
              f"{log.path}: statistics say {s.statistics.message_count} messages, the file holds {len(log.messages)}")
    if count is not None:
        ctx.check(len(log.messages) == count, f"{log.path}: {len(log.messages)} messages, want {count}")


def same_payloads(ctx, got, want, what, by_suffix=False, skip=()):
    """Every topic's payloads equal, message for message (but the topics named in `skip`)."""
    g = got.by_suffix() if by_suffix else {t: got.payloads(t) for t in got.topics()}
    w = want.by_suffix() if by_suffix else {t: want.payloads(t) for t in want.topics()}
    g = {t: v for t, v in g.items() if t.rsplit("/", 1)[-1] not in skip}
    w = {t: v for t, v in w.items() if t.rsplit("/", 1)[-1] not in skip}
    ok = ctx.check(sorted(g) == sorted(w), f"{what}: topics {sorted(g)} != {sorted(w)}")
    for t in sorted(set(g) & set(w)):
        a, b = g[t], w[t]
        if len(a) != len(b):
            ok = ctx.check(False, f"{what}: {t}: {len(a)} messages, want {len(b)}") and ok
            continue
        diff = next((i for i in range(len(a)) if a[i] != b[i]), None)
        ok = ctx.check(diff is None, f"{what}: {t}: message {diff} differs ({len(a[diff or 0])} vs "
                                     f"{len(b[diff or 0])} bytes)") and ok
    if ok:
        n = sum(len(v) for v in g.values())
        ctx.log(f"{what}: {n} payloads on {len(g)} topics identical, message for message")
    return ok


def contiguous_slice(part, whole):
    """True when `part` equals whole[k:k+len(part)] for some k (found from part's first element)."""
    if not part:
        return False
    for k in (i for i, x in enumerate(whole) if x == part[0]):
        if whole[k:k + len(part)] == part:
            return True
    return False


def rbsim_check(ctx, run, golden, name, live, timeout=300):
    """`rbsim check RUN GOLDEN` must pass; a live recording's log times are receive times, so
    they are not compared for it (--ignore-log-time)."""
    args = ["check", run, golden] + (["--ignore-log-time"] if live else [])
    rc, out, err = ctx.rbrun(name, *args, ok=False, timeout=timeout)
    ctx.check(rc == 0, f"rbsim {' '.join(args)} exited with {rc}\n{out}{err}")


def record_args(ctx, out, *extra, ns=None, domain=None):
    return ("record", out, "--domain", domain if domain is not None else ctx.domain, "--namespace", ns or ctx.ns,
            *extra)


def node_args(ctx, scene, *extra, ns=None, domain=None):
    return ("node", scene, "--domain", domain if domain is not None else ctx.domain, "--namespace", ns or ctx.ns,
            *extra)


def golden_every(ctx, scene):
    _, out, _ = ctx.rbrun("golden-every", "check", "--golden-every", scene, timeout=30)
    ctx.require(out.strip().isdigit(), f"rbsim check --golden-every printed {out!r}")
    return int(out.strip())


def counts_line(proc):
    """(received, lost) from the recorder's closing line."""
    for line in proc.stderr().splitlines():
        if line.startswith("rbsim record:") and "messages received" in line:
            words = line.split()
            return int(words[2]), int(words[5])
    return None


# ---------------------------------------------------------------------------------------------
# Cases


def live_recording(ctx, scene, every, out, tag, env=None, steps_total=None):
    """Recorder first, then the node (--rate 0, --wait-for-subscribers 1): the complete run."""
    expected = len(LATCHED) + len(PER_STEP) * (steps_total // every + 1)
    rec = ctx.rb(f"record-{tag}", *record_args(ctx, out, "--max-messages", expected, "--wall-duration", 90), env=env)
    node = ctx.rb(f"node-{tag}", *node_args(ctx, scene, "--rate", 0, "--publish-every", every,
                                            "--wait-for-subscribers", 1), env=env)
    exited_ok(ctx, node, 90)
    exited_ok(ctx, rec, 90)
    ctx.check(counts_line(rec) == (expected, 0),
              f"recorder reports {counts_line(rec)} (received, lost), want ({expected}, 0)\n{rec.output()}")
    # The latched scene description comes first, in the file and in log time, whatever order
    # discovery delivered the topics in (tools that read the recording rely on it).
    first_in_file = read_stream_messages(out)[0][0]
    first_in_time = Log(out).messages[0][0]
    ctx.check(first_in_file.endswith("/scene") and first_in_time.endswith("/scene"),
              f"{out}: first message on {first_in_file} (file order), {first_in_time} (log time), want the scene")
    # The latched markers once, before every per-step message; /tf every published step.
    in_file = [m[0] for m in read_stream_messages(out)]
    markers = [i for i, t in enumerate(in_file) if t.endswith("/markers")]
    per_step = [i for i, t in enumerate(in_file) if t.rsplit("/", 1)[-1] in PER_STEP]
    ctx.check(len(markers) == 1, f"{out}: {len(markers)} markers messages, want 1 (latched)")
    ctx.check(bool(markers and per_step) and markers[0] < per_step[0],
              f"{out}: the markers are not written before the per-step messages")
    tf = sum(1 for t in in_file if t == "/tf")
    ctx.check(tf == steps_total // every + 1, f"{out}: {tf} /tf messages, want {steps_total // every + 1}")
    return expected


def case_node_record(ctx):
    """Node and recorder: the live recording equals `rbsim run --record`, message for message,
    and the golden log's payloads; the recording is a finished, indexed MCAP file."""
    scene = ctx.scene("airplane.xml")
    every = golden_every(ctx, scene)
    run = ctx.path("run.mcap")
    ctx.rbrun("run-record", "run", scene, "--record", run, "--record-every", every, "--namespace", ctx.ns)
    want = Log(run)
    steps = max(step_of(p) for p in want.by_suffix()["body_states"])
    live = ctx.path("live.mcap")
    expected = live_recording(ctx, scene, every, live, "live", steps_total=steps)
    got = Log(live)
    expect_indexed(ctx, got, expected)
    ctx.check(first_published(got).endswith("/scene"), f"first published message is {first_published(got)}, "
                                                       f"not the scene")
    same_payloads(ctx, got, want, "live recording vs rbsim run --record")
    for suffix in ("scene", "body_states", "clock"):  # what the node offered, as rbsim run says
        ctx.check(got.offered(suffix) == want.offered(suffix) == (("keep_last", "1") if suffix == "scene"
                                                                  else ("keep_all", "0")),
                  f"offered_qos_profiles of {suffix}: live {got.offered(suffix)}, run {want.offered(suffix)}")
    golden = os.path.join(ctx.src, "test", "golden", "airplane.mcap")
    if os.path.exists(golden):
        # /tf and the markers name the body frames in the node's namespace, the golden's in rbsim's.
        same_payloads(ctx, got, Log(golden), "live recording vs golden test/golden/airplane.mcap", by_suffix=True,
                      skip=("tf", "markers"))
        gold_run = ctx.path("run-rbsim-ns.mcap")
        ctx.rbrun("run-record-rbsim", "run", scene, "--record", gold_run, "--record-every", every)
        rbsim_check(ctx, gold_run, golden, "check-run-golden", live=False)
    else:
        ctx.note(f"no golden log {golden}: golden comparison skipped")
    rbsim_check(ctx, live, run, "check-live-run", live=True)


def case_service_events(ctx):
    """REP 2012 service introspection over DDS: a node started with -p
    service_configure_introspection:=contents, `rbsim record --services pause,resume` beside it and an
    independent Python client (player_client.py's, with std_srvs/srv/Trigger) calling pause and resume:
    the recording holds /NS/pause/_service_event and /NS/resume/_service_event under the _Event types
    with the ros2msg schema and type hash rosbag2 would write, and `rosbags`, given only the recorded
    schema, decodes each event: REQUEST_RECEIVED then RESPONSE_SENT per call, the client's guid
    (rmw_cyclonedds's first 8 bytes of client_gid) and sequence number, the reply the client got."""
    import struct
    from player_client import Player, trigger_types
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    scene = ctx.scene("cantilever.xml")
    out = ctx.path("events.mcap")
    node = ctx.rb("node", *node_args(ctx, scene, "--loop", "--ros-args", "-p",
                                     "service_configure_introspection:=contents"))
    node.wait_for_text("rbsim node:", 30, stream="stderr")
    rec = ctx.rb("record", *record_args(ctx, out, "--services", "pause,resume", "--topics", "commands",
                                        "--wall-duration", 90, "--chunk-size", 1024))
    client = Player(ctx.domain, "/" + ctx.ns, "file://" + ctx.loopback_xml, names=("pause", "resume"),
                    types=trigger_types())
    ctx.require(client.wait_matched(20), "the Python client did not match the node's pause and resume in 20 s")
    topics = {name: f"/{ctx.ns}/{name}/_service_event" for name in ("pause", "resume")}
    replies = {}  # (service, seq) -> the reply the client got

    # Calls until the recorder, whose readers match the node's event writers some time after it
    # starts, has both events of a call on each topic (the calls before that are not recorded).
    def enough(got):
        for name in ("pause", "resume"):
            r = client.call(name)
            ctx.require(r is not None, f"no reply from {name} within 15 s\n{node.output()}")
            replies[(name, client.clients[name]["seq"])] = r
        counts = {t: sum(1 for m in got if m[0] == t) for t in topics.values()}
        return all(c >= 4 for c in counts.values())
    wait_recorded(ctx, rec, out, enough, 60, "two calls' events of pause and resume")
    rec.signal(signal.SIGINT)
    exited_ok(ctx, rec, 30)
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 30)

    log = Log(out)
    schemas = {ch.topic: log.summary.schemas[ch.schema_id] for ch in log.summary.channels.values()}
    store = get_typestore(Stores.EMPTY)
    for name, topic in topics.items():
        ctx.require(topic in schemas, f"{topic} not recorded: {log.topics()}")
        schema = schemas[topic]
        ctx.check(schema.name == "std_srvs/srv/Trigger_Event", f"{topic}: schema {schema.name}")
        ctx.check(schema.encoding == "ros2msg", f"{topic}: schema encoding {schema.encoding}")
        # The recorded schema alone, split as rosbag2 writes it, registered with rosbags.
        sections = schema.data.decode().split("\n" + "=" * 80 + "\n")
        types = dict(get_types_from_msg(sections[0], schema.name))
        for part in sections[1:]:
            head, _, text = part.partition("\n")
            types.update(get_types_from_msg(text, head.removeprefix("MSG: ")))
        store.register(types)
        events = [store.deserialize_cdr(p, "std_srvs/srv/msg/Trigger_Event") for p in log.payloads(topic)]
        ctx.require(len(events) >= 4 and len(events) % 2 == 0, f"{topic}: {len(events)} events")
        guid = client.clients[name]["guid"]
        for request, response in zip(events[::2], events[1::2]):
            info = request.info
            ctx.check(info.event_type == 1 and response.info.event_type == 2,
                      f"{topic}: event types {info.event_type}, {response.info.event_type} (want 1, 2)")
            ctx.check(bytes(info.client_gid.tolist()) == struct.pack("<Q", guid) + bytes(8),
                      f"{topic}: client_gid {info.client_gid.tolist()} (guid {guid:#x})")
            ctx.check(response.info.sequence_number == info.sequence_number,
                      f"{topic}: sequence numbers {info.sequence_number}, {response.info.sequence_number}")
            ctx.check(len(request.request) == 1 and len(request.response) == 0, f"{topic}: request event's sequences")
            got = response.response[0] if len(response.response) == 1 else None
            want = replies.get((name, info.sequence_number))
            ctx.check(got is not None and want is not None and (got.success, got.message) ==
                      (want.success, want.message),
                      f"{topic}: seq {info.sequence_number}: recorded reply {got}, the client got {want}")
            ctx.check(abs(info.stamp.sec - time.time()) < 600, f"{topic}: stamp {info.stamp} not the system clock")


def case_late_recorder(ctx):
    """A recorder started after the node still gets the scene description (transient local) and
    then every step, contiguous and byte-equal to the run; SIGTERM finishes a valid file."""
    scene = ctx.scene("cantilever.xml")
    every = 10
    run = ctx.path("run.mcap")
    ctx.rbrun("run-record", "run", scene, "--record", run, "--record-every", every, "--namespace", ctx.ns)
    want = Log(run)
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 1, "--publish-every", every))
    node.wait_for_text("rbsim node:", 20, stream="stderr")
    time.sleep(1.5)
    late = ctx.path("late.mcap")
    # Small chunks: what it recorded can be read from the file it is writing.
    rec = ctx.rb("record-late", *record_args(ctx, late, "--chunk-size", 1024))
    rec.wait_for_text("recording", 20, stream="stderr")
    # Until it has recorded more than 20 of every per-step topic (not a fixed time: on a busy
    # machine matching the node's writers alone can take seconds).
    wait_recorded(ctx, rec, late, lambda got: all(per_topic(got).get(t, 0) > 20 for t in PER_STEP), 60,
                  "more than 20 messages of every per-step topic")
    ctx.require(node.alive(), f"the node stopped\n{node.output()}")
    rec.signal(signal.SIGTERM)
    exited_ok(ctx, rec, 15, "recorder stopped with SIGTERM")
    ctx.check(node.alive(), "the node stopped when the recorder left")
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 15, "node stopped with SIGINT")
    counts = counts_line(rec)
    ctx.check(counts is not None and counts[0] > 0 and counts[1] == 0, f"recorder counts {counts}\n{rec.output()}")
    got = Log(late)
    expect_indexed(ctx, got)
    g = got.by_suffix()
    w = want.by_suffix()
    for t in LATCHED:
        ctx.check(g.get(t) == w[t], f"late recorder: {t} {len(g.get(t, []))} messages, want the run's one "
                                    f"(transient local)")
    for t in PER_STEP:
        part = g.get(t, [])
        ctx.check(len(part) > 20, f"late recorder: only {len(part)} {t} messages")
        ctx.check(contiguous_slice(part, w[t]), f"late recorder: {t} is not a contiguous, byte-equal part of the run")
    steps = [step_of(p) for p in g.get("body_states", [])]
    if steps:
        ctx.check(steps[0] > 0, "late recorder got step 0: it was not late")
        ctx.log(f"late recorder: scene + steps {steps[0]}..{steps[-1]} (every {every})")


def case_replay_roundtrip(ctx):
    """run --record -> replay -> record, and node -> record -> replay -> record: same payloads."""
    scene = ctx.scene("airplane.xml")
    every = 100
    x = ctx.path("run.mcap")
    ctx.rbrun("run-record", "run", scene, "--record", x, "--record-every", every, "--namespace", ctx.ns)
    want = Log(x)
    n = len(want.messages)
    r1 = ctx.path("replayed.mcap")
    rec = ctx.rb("record-replayed", *record_args(ctx, r1, "--max-messages", n, "--wall-duration", 90))
    rep = ctx.rb("replay-run", "replay", x, "--domain", ctx.domain, "--rate", 0, "--wait-for-subscribers", 1)
    exited_ok(ctx, rep, 90)
    exited_ok(ctx, rec, 90)
    got = Log(r1)
    expect_indexed(ctx, got, n)
    ctx.check(first_published(got).endswith("/scene"), f"first replayed message is {first_published(got)}, "
                                                       f"not the scene")
    same_payloads(ctx, got, want, "rbsim run --record -> replay -> record")
    rbsim_check(ctx, r1, x, "check-replayed-run", live=True)

    # Live round trip: node -> record L -> replay L -> record L2.
    steps = max(step_of(p) for p in want.by_suffix()["body_states"])
    live = ctx.path("live.mcap")
    live_recording(ctx, scene, every, live, "live", steps_total=steps)
    lv = Log(live)
    same_payloads(ctx, lv, want, "live recording vs rbsim run --record")
    l2 = ctx.path("live-replayed.mcap")
    rec2 = ctx.rb("record-live-replayed", *record_args(ctx, l2, "--max-messages", len(lv.messages), "--wall-duration", 90))
    rep2 = ctx.rb("replay-live", "replay", live, "--domain", ctx.domain, "--rate", 0, "--wait-for-subscribers", 1)
    exited_ok(ctx, rep2, 90)
    exited_ok(ctx, rec2, 90)
    l2log = Log(l2)
    expect_indexed(ctx, l2log, len(lv.messages))
    same_payloads(ctx, l2log, lv, "record -> replay -> record round trip")
    rbsim_check(ctx, l2, live, "check-roundtrip", live=True)


def case_replay_options(ctx):
    """--rate, --topics, --namespace, --clock, --start-offset, --loop, Ctrl-C (exit 0)."""
    scene = ctx.scene("cantilever.xml")
    every = 20
    x = ctx.path("run.mcap")
    ctx.rbrun("run-record", "run", scene, "--duration", 2, "--record", x, "--record-every", every,
              "--namespace", ctx.ns)
    want = Log(x)
    w = want.by_suffix()
    n = len(want.messages)
    per_step = len(w["body_states"])  # 101: steps 0, 20, ..., 2000
    ctx.require(per_step == 101, f"run --duration 2 --record-every 20 gave {per_step} body states, want 101")

    def replay_into(tag, replay_extra, max_messages, ns=None, rec_extra=()):
        out = ctx.path(f"{tag}.mcap")
        # The recorder stops on its own once it has every message the replay sends (not a time
        # after the replay ended: what is still on its way would be lost to a Ctrl-C).
        rec = ctx.rb(f"record-{tag}", *record_args(ctx, out, "--max-messages", max_messages, *rec_extra,
                                                   "--wall-duration", 60, ns=ns))
        rep = ctx.rb(f"replay-{tag}", "replay", x, "--domain", ctx.domain, "--wait-for-subscribers", 1,
                     *replay_extra)
        t = time.monotonic()
        exited_ok(ctx, rep, 60)
        wall = time.monotonic() - t
        exited_ok(ctx, rec, 60)
        return Log(out), wall

    # --rate 2: 2 s of log time in about 1 s, the recorded log-time gaps halved.
    got, wall = replay_into("rate2", ("--rate", 2), max_messages=n)
    same_payloads(ctx, got, want, "replay --rate 2")
    lt = [m[2] for m in got.messages if m[0].endswith("/body_states")]
    span = (lt[-1] - lt[0]) * 1e-9 if lt else 0.0
    ctx.check(0.85 <= span <= 1.6, f"replay --rate 2 of 2 s of log: body states spread over {span:.3f} s, want ~1 s")
    ctx.log(f"--rate 2: body states spread over {span:.3f} s of wall time (replay process {wall:.2f} s)")

    # --topics: only the scene description, the markers, the body states and /tf.
    # (with --keep-last 5000, more than the log holds: nothing can be dropped, and the recording
    # says what the replay offered, like rosbag2 records a publisher's QoS)
    chosen = ("body_states", "markers", "scene", "tf")
    got, _ = replay_into("topics", ("--rate", 0, "--topics", f"body_states,/{ctx.ns}/scene,markers,/tf", "--keep-last",
                                    5000), max_messages=sum(len(w[t]) for t in chosen))
    ctx.check(got.offered("body_states") == ("keep_last", "5000") and got.offered("scene") == ("keep_last", "1")
              and got.offered("markers") == ("keep_last", "1"),
              f"replay --keep-last 5000: recorded offers {got.offered('body_states')}, {got.offered('scene')}, "
              f"{got.offered('markers')}")
    g = got.by_suffix()
    ctx.check(sorted(g) == ["body_states", "markers", "scene", "tf"], f"replay --topics: recorded {sorted(g)}")
    ctx.check(all(g.get(t) == w[t] for t in ("body_states", "markers", "scene", "tf")),
              "replay --topics: payloads differ from the log's")

    # --namespace: the same payloads under another namespace.
    other = ctx.ns + "_remap"
    got, _ = replay_into("namespace", ("--rate", 0, "--namespace", other), max_messages=n, ns=other)
    ctx.check(all(t in ("/clock", "/tf") or t.startswith(f"/{other}/") for t in got.topics()),
              f"replay --namespace: topics {got.topics()}")
    same_payloads(ctx, got, want, "replay --namespace", by_suffix=True)

    # --clock: /clock carries the log time of each message; a run's log time is simulated time,
    # so the published clock equals the recorded one (which is not replayed on top of it).
    got, _ = replay_into("clock", ("--rate", 0, "--clock"), max_messages=n)
    same_payloads(ctx, got, want, "replay --clock")
    clocks = [stamp_of(p) for p in got.by_suffix().get("clock", [])]
    ctx.check(clocks == [(s // 10**9, s % 10**9) for s in sorted({m[2] for m in want.messages})],
              "replay --clock: /clock values are not the log times")

    # --start-offset 1: the scene description first, then steps from 1000 (t = 1 s) on.
    at_1s = next(m[2] for m in want.messages if m[0].endswith("/body_states") and step_of(m[5]) == 1000)
    got, _ = replay_into("offset", ("--rate", 0, "--start-offset", 1.0),
                         max_messages=len(LATCHED) + sum(1 for m in want.messages if m[2] >= at_1s and
                                                         m[0].rsplit("/", 1)[-1] not in LATCHED))
    g = got.by_suffix()
    ctx.check(bool(got.messages) and first_published(got).endswith("/scene"),
              f"replay --start-offset: first published {first_published(got)}, not the scene")
    for t in LATCHED:
        ctx.check(g.get(t) == w[t], f"replay --start-offset: {t} missing or different")
    steps = [step_of(p) for p in g.get("body_states", [])]
    ctx.check(steps == list(range(1000, 2001, every)), f"replay --start-offset 1: steps {steps[:3]}..{steps[-3:]}")
    ctx.check(g.get("body_states") == w["body_states"][50:], "replay --start-offset: payloads differ")

    # --loop: passes repeat (scene + steps 0..2000 each) until Ctrl-C, which exits 0. At --rate 10
    # a pass takes 0.2 s: the recorder (there before the replay starts) sees several.
    out = ctx.path("loop.mcap")
    rec = ctx.rb("record-loop", *record_args(ctx, out, "--chunk-size", 1024))
    rep = ctx.rb("replay-loop", "replay", x, "--domain", ctx.domain, "--rate", 10, "--loop",
                 "--wait-for-subscribers", 1)
    rep.wait_for_text("waiting", 20, stream="stderr")
    # Until the recorder's file holds two whole passes (not a time: matching may take seconds).
    wait_recorded(ctx, rec, out, lambda got: per_topic(got).get("body_states", 0) >= 2 * per_step, 60,
                  "two passes of body states")
    ctx.check(rep.alive(), "replay --loop ended by itself")
    rep.signal(signal.SIGINT)
    exited_ok(ctx, rep, 15, "replay --loop stopped with SIGINT")
    rec.signal(signal.SIGINT)
    exited_ok(ctx, rec, 15, "recorder of the looping replay")
    g = Log(out).by_suffix()
    steps = [step_of(p) for p in g.get("body_states", [])]
    one = list(range(0, 2001, every))
    ctx.check(steps[:2 * per_step] == one + one, f"replay --loop: body-state steps {steps[:3]}... "
                                                 f"({len(steps)}) are not two passes")
    ctx.check(len(g.get("scene", [])) >= 2, f"replay --loop: {len(g.get('scene', []))} scene descriptions, want one "
                                            f"per pass")
    ctx.check(len(g.get("markers", [])) >= 2, f"replay --loop: {len(g.get('markers', []))} markers, want one per pass")
    ctx.log(f"--loop: {len(steps) / per_step:.1f} passes recorded at --rate 10")

    # Ctrl-C while waiting for subscribers, and in the middle of a paced replay: exit 0.
    rep = ctx.rb("replay-wait-int", "replay", x, "--domain", ctx.domain, "--namespace", ctx.ns + "_nobody",
                 "--wait-for-subscribers", 1)
    # The line comes just before the wait: a SIGINT after it stops the wait (or the check before it).
    rep.wait_for_text("waiting", 20, stream="stderr")
    rep.signal(signal.SIGINT)
    exited_ok(ctx, rep, 10, "replay stopped with SIGINT while waiting")
    ctx.check("stopped while waiting, nothing published" in rep.stderr(),
              f"replay stopped while waiting: no 'stopped while waiting' line\n{rep.output()}")
    # Without a wait for subscribers, playing starts right after the start line; at --rate 0.25
    # the 2 s log takes 8 s.
    rep = ctx.rb("replay-mid-int", "replay", x, "--domain", ctx.domain, "--namespace", ctx.ns + "_nobody",
                 "--rate", 0.25)
    rep.wait_for_text("rbsim replay:", 20, stream="stderr")
    ctx.check(rep.alive(), "replay --rate 0.25 of 2 s ended right after its start line")
    rep.signal(signal.SIGINT)
    exited_ok(ctx, rep, 10, "replay stopped with SIGINT while replaying")
    ctx.check("rbsim replay: stopped after 0 complete passes" in rep.stderr(),
              f"replay stopped while replaying: no end line saying so\n{rep.output()}")


def case_player(ctx):
    """rosbag2's player services on /rbsim_player/..., called by an independent Python client
    (test/e2e/player_client.py) while a recorder records what the replay publishes: --start-paused
    sends only the latched topics; set_rate/get_rate round trip, rates <= 0 refused; play_next
    publishes exactly one message and burst N exactly N, only while paused; a pause holds; a seek
    re-sends the scene description and the markers and the next messages are at that simulated
    time; /clock jumps there; a pause while playing holds and set_rate paces; a progress line on a
    terminal, none when piped; --playback-until, --playback-duration and --delay. The recording's
    publish times (the replay's source timestamps) say which call each message followed."""
    from player_client import Player

    scene = ctx.scene("cantilever.xml")
    every = 20
    x = ctx.path("run.mcap")
    ctx.rbrun("run-record", "run", scene, "--duration", 2, "--record", x, "--record-every", every,
              "--namespace", ctx.ns)
    want = Log(x)
    per_step_topics = {m[0] for m in want.messages if m[0].rsplit("/", 1)[-1] not in LATCHED}
    per_step_count = len([m for m in want.messages if m[0] in per_step_topics])
    out = ctx.path("player.mcap")
    # Small chunks: what the recorder got can be read from the file it is writing.
    rec = ctx.rb("record", *record_args(ctx, out, "--wall-duration", 90, "--chunk-size", 1024))
    rep = ctx.rb("replay", "replay", x, "--domain", ctx.domain, "--start-paused", "--clock",
                 "--wait-for-subscribers", 1)
    player = Player(ctx.domain, "/rbsim_player", "file://" + ctx.loopback_xml)
    ctx.require(player.wait_matched(20), "the Python client did not match the player's nine services in 20 s")
    marks = {}

    def mark(name):
        time.sleep(0.4)  # what the last call published has arrived (loopback) before the next mark
        marks[name] = time.time_ns()

    def call(name, **fields):
        r = player.call(name, **fields)
        ctx.require(r is not None, f"no reply from /rbsim_player/{name} within 15 s\n{rep.output()}")
        return r

    # The replay started (paused) once the recorder matched it: it has published the latched
    # topics, which the marks below count as before the first call (each fills a 1 KiB chunk).
    wait_recorded(ctx, rec, out, lambda got: all(t in per_topic(got) for t in LATCHED), 60,
                  "the latched scene description and markers")
    ctx.check(call("is_paused").paused, "is_paused: false after --start-paused")
    ctx.check(call("get_rate").rate == 1.0, "get_rate: not 1 (the default --rate)")
    for bad in (0.0, -2.0):
        ctx.check(not call("set_rate", rate=bad).success, f"set_rate({bad}) accepted (want refused: rate <= 0)")
    ctx.check(call("set_rate", rate=3.5).success, "set_rate(3.5) refused")
    ctx.check(call("get_rate").rate == 3.5, "get_rate after set_rate(3.5)")
    mark("start_play_next")
    ctx.check(call("play_next").success, "play_next while paused: success false")
    mark("end_play_next")
    r = call("burst", num_messages=5)
    ctx.check(r.actually_burst == 5, f"burst 5 while paused: actually_burst {r.actually_burst}")
    mark("end_burst")
    time.sleep(0.8)  # paused: nothing more may go out
    mark("end_hold")
    # Seek to simulated t = 1 s while paused: scene and markers again, /clock at 1 s.
    ctx.check(call("seek", time=player.Time(sec=1, nanosec=0)).success, "seek to 1 s: success false")
    ctx.check(not call("seek", time=player.Time(sec=100, nanosec=0)).success, "seek past the end accepted")
    mark("end_seek")
    ctx.check(call("play_next").success, "play_next after the seek: success false")
    mark("end_play_next2")
    ctx.check(call("is_paused").paused, "is_paused: false before resume")
    ctx.check(call("set_rate", rate=0.5).success, "set_rate(0.5) refused")
    call("toggle_paused")  # playing at half speed
    ctx.check(not call("is_paused").paused, "is_paused: true after toggle_paused")
    ctx.check(not call("play_next").success, "play_next while playing: success true (rosbag2: paused only)")
    time.sleep(0.6)
    call("pause")
    mark("paused_again")
    time.sleep(0.8)  # a pause while playing holds too
    mark("end_hold2")
    ctx.check(call("is_paused").paused, "is_paused: false after pause")
    ctx.check(call("set_rate", rate=4.0).success, "set_rate(4) refused")
    call("resume")  # the rest of the log at 4x
    exited_ok(ctx, rep, 30, "replay after resume")
    time.sleep(0.5)
    rec.signal(signal.SIGINT)
    exited_ok(ctx, rec, 15, "recorder of the player")

    ctx.check("\r" not in rep.stderr() and "[paused]" not in rep.stderr(),
              f"replay piped: a progress line on stderr\n{rep.stderr()}")
    # On a terminal: the progress line (clock, rate, paused), cleared at the end.
    import pty
    master, slave = pty.openpty()
    tty = subprocess.Popen([ctx.rbsim, "replay", x, "--domain", str(ctx.domain), "--namespace", ctx.ns + "_tty",
                            "--start-paused", "--rate", "2"], env=ctx.env(), stdin=subprocess.DEVNULL,
                           stdout=subprocess.DEVNULL, stderr=slave, preexec_fn=_child_setup())
    os.close(slave)
    text = b""
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and b"[paused]" not in text:
        import select
        if select.select([master], [], [], 0.2)[0]:
            try:
                text += os.read(master, 4096)
            except OSError:
                break
    tty.send_signal(signal.SIGINT)
    try:
        tty_rc = tty.wait(timeout=10)
    except subprocess.TimeoutExpired:
        tty.kill()
        tty_rc = None
    os.close(master)
    line = text.decode(errors="replace")
    ctx.check("[paused] log 0.000 / 2.000 s" in line and "rate 2x" in line,
              f"replay on a terminal: no progress line with the clock, rate and paused state in {line!r}")
    ctx.check(tty_rc == 0, f"replay on a terminal stopped with SIGINT exited with {tty_rc}")

    got = Log(out)
    # (suffix, publish time, payload) in publish order (the replay's source timestamps)
    msgs = sorted(((m[0].rsplit("/", 1)[-1], m[3], m[5]) for m in got.messages), key=lambda m: m[1])

    def between(a, b):
        lo = marks.get(a, 0)
        hi = marks.get(b, 1 << 63)
        return [m for m in msgs if lo <= m[1] < hi]

    first = between(None, "start_play_next")
    ctx.check(sorted({m[0] for m in first}) == sorted(LATCHED),
              f"--start-paused: published {sorted({m[0] for m in first})} before play_next, want only {LATCHED}")
    one = [m for m in between("start_play_next", "end_play_next") if m[0] != "clock"]
    ctx.check(len(one) == 1 and one[0][0] not in LATCHED,
              f"play_next while paused published {[m[0] for m in one]}, want exactly one per-step message")
    five = [m for m in between("end_play_next", "end_burst") if m[0] != "clock"]
    ctx.check(len(five) == 5, f"burst 5 published {len(five)} messages ({[m[0] for m in five]})")
    held = between("end_burst", "end_hold")
    ctx.check(not held, f"paused: {len(held)} messages published while paused ({[m[0] for m in held]})")
    seek = between("end_hold", "end_seek")
    ctx.check(sorted(m[0] for m in seek if m[0] != "clock") == sorted(LATCHED),
              f"seek: published {[m[0] for m in seek]}, want the scene description and the markers again")
    clocks = [stamp_of(m[2]) for m in seek if m[0] == "clock"]
    ctx.check(clocks == [(1, 0)], f"seek to 1 s: /clock published {clocks}, want one jump to (1, 0)")
    nxt = [m for m in between("end_seek", "end_play_next2") if m[0] != "clock"]
    ctx.check(len(nxt) == 1 and sim_stamp(nxt[0][0], nxt[0][2]) == (1, 0),
              f"play_next after seek to 1 s: {[(m[0], sim_stamp(m[0], m[2])) for m in nxt]}, want one at (1, 0)")
    half = [m for m in between("end_play_next2", "paused_again") if m[0] == "body_states"]
    if ctx.check(len(half) >= 5, f"{len(half)} body states in 0.6 s at rate 0.5 (want about 15)"):
        sim = (sim_stamp("body_states", half[-1][2])[0] - sim_stamp("body_states", half[0][2])[0]) * 1e9 + \
            sim_stamp("body_states", half[-1][2])[1] - sim_stamp("body_states", half[0][2])[1]
        wall = half[-1][1] - half[0][1]
        ctx.check(1.5 <= wall / sim <= 3.0, f"rate 0.5: {wall * 1e-9:.3f} s of wall time for {sim * 1e-9:.3f} s "
                                            f"of log, want about twice as long")
    held = between("paused_again", "end_hold2")
    ctx.check(not held, f"pause while playing: {len(held)} messages published while paused")
    rest = between("end_play_next2", None)
    steps = [step_of(m[2]) for m in rest if m[0] == "body_states"]
    ctx.check(bool(steps) and steps[0] in (1000, 1000 + every) and steps == list(range(steps[0], 2001, every)),
              f"after the seek: body-state steps {steps[:3]}..{steps[-3:]}, want every one from step 1000 on to "
              f"2000 across pause and resume")
    # Everything published was one of the recording's messages (the latched ones more than once).
    recorded = {m[5] for m in want.messages}
    ctx.check(all(m[2] in recorded for m in msgs if m[0] != "clock"), "a published payload is not in the recording")
    # --playback-until (simulated time), --playback-duration (log time after --start-offset), --delay.
    # The recorder stops by itself once it has every message the replay sends (the latched two and
    # the per-step messages of steps first..last), not at a time after the replay ended.
    def log_time_of(step):
        return next(m[2] for m in want.messages if m[0].endswith("/body_states") and step_of(m[5]) == step)

    def sent(first, last):
        lo, hi = log_time_of(first), log_time_of(last)
        return len(LATCHED) + sum(1 for m in want.messages
                                  if m[0].rsplit("/", 1)[-1] not in LATCHED and lo <= m[2] <= hi)

    def bounded(tag, count, *extra):
        path = ctx.path(f"{tag}.mcap")
        r = ctx.rb(f"record-{tag}", *record_args(ctx, path, "--max-messages", count, "--wall-duration", 60))
        t0 = time.time_ns()
        p = ctx.rb(f"replay-{tag}", "replay", x, "--domain", ctx.domain, "--rate", 0, "--wait-for-subscribers", 1,
                   "--node-name", f"player_{tag}", *extra)
        exited_ok(ctx, p, 60)
        exited_ok(ctx, r, 60)
        ctx.check(counts_line(r) == (count, 0), f"recorder of replay {' '.join(map(str, extra))}: (received, lost) "
                                                f"{counts_line(r)}, want ({count}, 0)\n{r.output()}")
        log = Log(path)
        return [step_of(m[5]) for m in log.messages if m[0].endswith("/body_states")], log, t0

    steps, _, _ = bounded("until", sent(0, 500), "--playback-until", 0.5)
    ctx.check(steps == list(range(0, 501, every)), f"--playback-until 0.5: steps {steps[:2]}..{steps[-2:]}")
    steps, _, _ = bounded("duration", sent(1000, 1300), "--start-offset", 1, "--playback-duration", 0.3)
    ctx.check(steps == list(range(1000, 1301, every)),
              f"--start-offset 1 --playback-duration 0.3: steps {steps[:2]}..{steps[-2:]}")
    steps, log, t0 = bounded("delay", len(want.messages), "--delay", 1.5)
    first = min(m[3] for m in log.messages) if log.messages else 0
    ctx.check(len(steps) == 101 and first - t0 >= 1.5e9,
              f"--delay 1.5: {len(steps)} body states, the first message {(first - t0) * 1e-9:.2f} s after the start")

    ctx.log(f"player: {len(msgs)} messages recorded ({per_step_count} per-step in the log); marks at "
            + ", ".join(f"{k} {(v - marks['start_play_next']) * 1e-9:+.2f} s" for k, v in marks.items()))


def case_subscribers_come_and_go(ctx):
    """The node keeps running while recorders and a Python subscriber come and go (clean exits,
    SIGKILL); a SIGKILLed recorder's file is repaired by `rbsim log recover`. After a clean
    leave the stream normally goes on without a gap; after a SIGKILL it may stall until DDS
    declares the dead reader gone (the participant lease duration, 2 s in rbsim's loopback
    configuration): bounded here, measured and reported."""
    scene = ctx.scene("cantilever.xml")
    states = f"/{ctx.ns}/body_states"
    # Rate 1, every 5th step of dt = 1 ms: 200 body states per second.
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 1, "--publish-every", 5, "--loop"))
    node.wait_for_text("rbsim node:", 20, stream="stderr")

    def alive(after):
        ctx.require(node.alive(), f"the node stopped after {after}\n{node.output()}")

    def max_gap(log):
        t = [m[2] for m in log.messages if m[0] == states]
        return max((b - a for a, b in zip(t, t[1:])), default=0) * 1e-9

    # 1: a recorder that stops by itself, once it has 300 messages (not after a wall time, which
    # counts from its start, discovery included: seen 1.4 s).
    rec = ctx.rb("record-1", *record_args(ctx, ctx.path("r1.mcap"), "--max-messages", 300, "--wall-duration", 60))
    exited_ok(ctx, rec, 90)
    n1 = len(Log(ctx.path("r1.mcap")).payloads(states)) if os.path.exists(ctx.path("r1.mcap")) else 0
    ctx.check(n1 > 0 and counts_line(rec) == (300, 0),
              f"recorder 1: {n1} body states, (received, lost) {counts_line(rec)}, want (300, 0)\n{rec.output()}")
    alive("a recorder finished")

    # 2: right after a clean leave, a recorder stopped with SIGINT: no gap, a valid indexed file.
    r2 = ctx.path("r2.mcap")
    rec = ctx.rb("record-2", *record_args(ctx, r2, "--chunk-size", 1024))
    rec.wait_for_text("recording", 20, stream="stderr")
    # Until it has recorded more than 150 body states (discovery of a new participant on loopback
    # can take over a second, seen: 1.4 s); the gap check below only looks at what arrived after
    # matching.
    wait_recorded(ctx, rec, r2, lambda got: per_topic(got).get("body_states", 0) > 150, 60, "150 body states")
    rec.signal(signal.SIGINT)
    exited_ok(ctx, rec, 15, "recorder stopped with SIGINT")
    log2 = Log(r2)
    expect_indexed(ctx, log2)
    n2, gap2 = len(log2.payloads(states)), max_gap(log2)
    ctx.check(n2 > 150, f"recorder 2 (after a clean leave) got {n2} body states, want > 150")
    # Usually ~10 ms. Seen once in some 20 runs on a loaded machine: 1.8 s, i.e. the node went on
    # waiting for the departed recorder's acknowledgements until its lease (2 s) ran out, as if
    # the leave had not reached it. Bounded by the lease here; a longer stall fails.
    ctx.check(gap2 < 2.5, f"recorder 2 (after a clean leave): the body states stalled {gap2:.2f} s, longer "
                          f"than the 2 s lease")
    if gap2 >= 0.5:
        ctx.note(f"after a clean leave the node stalled {gap2:.2f} s (lease-bound)")
    ctx.log(f"after a clean leave: {n2} body states, largest gap {gap2 * 1e3:.0f} ms")
    alive("a recorder was stopped with SIGINT")

    # 3: a Python subscriber, SIGKILLed.
    sub = ctx.start("python-sub", [sys.executable, os.path.join(os.path.dirname(__file__), "dds_subscriber.py"),
                                   "--domain", str(ctx.domain), "--namespace", ctx.ns, "--count", "1000000",
                                   "--timeout", "30", "--out", ctx.path("sub.jsonl")],
                    env=ctx.env(uri="file://" + ctx.loopback_xml))
    sub.wait_for_text("READY", 30)

    def received():
        try:
            with open(ctx.path("sub.jsonl")) as f:
                return sum(1 for _ in f)
        except FileNotFoundError:
            return 0

    # Until it has received something (discovery can take over a second), at most 15 s.
    deadline = time.monotonic() + 15
    while received() == 0 and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(0.5)
    sub.signal(signal.SIGKILL)
    sub.wait(10)
    alive("a Python subscriber was killed")
    ctx.check(received() > 0, "the Python subscriber received nothing in 15 s")

    # 4: a recorder SIGKILLed after a few chunks: rbsim log recover saves its complete chunks.
    killed = ctx.path("killed.mcap")
    rec = ctx.rb("record-killed", *record_args(ctx, killed, "--compression", "none"))
    rec.wait_for_text("recording", 20, stream="stderr")
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and (not os.path.exists(killed) or os.path.getsize(killed) < 2_500_000):
        time.sleep(0.1)
    rec.signal(signal.SIGKILL)
    killed_at = time.time_ns()
    rec.wait(10)
    alive("a recorder was killed")
    ctx.check(os.path.getsize(killed) >= 2_500_000, f"killed recorder wrote {os.path.getsize(killed)} bytes in 30 s")
    check_recover(ctx, killed, "killed recorder")

    # 5: a newcomer after the SIGKILL gets the stream within the lease bound; then a clean stop.
    r5 = ctx.path("r5.mcap")
    rec = ctx.rb("record-5", *record_args(ctx, r5, "--max-messages", 600, "--wall-duration", 20))
    exited_ok(ctx, rec, 40)
    log5 = Log(r5)
    t5 = [m[2] for m in log5.messages if m[0] == states]
    ctx.check(log5.payloads(f"/{ctx.ns}/scene") != [], "recorder 5: no scene description")
    if ctx.check(len(t5) > 0, f"recorder 5: no body states within 20 s of a subscriber being killed"):
        stall = (t5[0] - killed_at) * 1e-9
        ctx.check(stall < 12.0, f"recorder 5: first body state {stall:.1f} s after the SIGKILL (lease bound 12 s)")
        ctx.note(f"after a subscriber was SIGKILLed the node's stream stalled {stall:.1f} s for newcomers "
                 f"(until DDS declared the dead reader gone: participant lease duration)")
    alive("the newcomer left")
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 15, "node stopped with SIGINT")


def check_recover(ctx, damaged, what):
    """`rbsim log recover` (when built) repairs the file; else the complete chunks are read."""
    fixed = damaged.replace(".mcap", "-recovered.mcap")
    rc, out, err = ctx.rbrun(f"recover-{os.path.basename(damaged)}", "log", "recover", damaged, fixed, ok=False,
                             timeout=60)
    if "recover" in (out + err) and os.path.exists(fixed):
        ctx.check(rc in (0, 1), f"rbsim log recover exited with {rc}\n{out}{err}")
        log = Log(fixed)
        expect_indexed(ctx, log)
        complete = read_stream_messages(damaged)
        ctx.check(len(log.messages) > 0 and len(log.messages) == len(complete),
                  f"{what}: recovered {len(log.messages)} messages, the complete chunks hold {len(complete)}")
        recovered = sorted((m[0], m[2], m[5]) for m in log.messages)  # topic, log time, payload
        ctx.check(recovered == sorted((m[0], m[1], m[4]) for m in complete),
                  f"{what}: the recovered messages differ from those in the complete chunks")
        ctx.log(f"{what}: rbsim log recover saved {len(log.messages)} messages")
        return log
    ctx.note(f"rbsim log recover not available ({rc}): complete chunks read with the Python reader")
    complete = read_stream_messages(damaged)
    ctx.check(len(complete) > 0, f"{what}: no complete chunk readable")
    return None


def case_python_subscriber(ctx):
    """An independent subscriber (Python cyclonedds, types from our IDL) decodes body states and
    PoseArray equal to `rbsim run --csv`, bit for bit."""
    scene = ctx.scene("cantilever.xml")
    every, duration = 20, 2
    csv_path = ctx.path("run.csv")
    ctx.rbrun("run-csv", "run", scene, "--duration", duration, "--csv", csv_path)
    rows = {}
    with open(csv_path) as f:
        header = f.readline().strip().split(",")
        col = {name: i for i, name in enumerate(header)}
        for line in f:
            v = line.strip().split(",")
            rows.setdefault(int(v[col["step"]]), []).append(v)
    steps = list(range(0, max(rows) + 1, every))
    ctx.require(steps[-1] == 2000, f"CSV steps end at {max(rows)}")
    env = ctx.env(uri="file://" + ctx.loopback_xml)
    out = ctx.path("sub.jsonl")
    sub = ctx.start("python-sub", [sys.executable, os.path.join(os.path.dirname(__file__), "dds_subscriber.py"),
                                   "--domain", str(ctx.domain), "--namespace", ctx.ns, "--count", str(len(steps)),
                                   "--timeout", "60", "--out", out], env=env)
    sub.wait_for_text("READY", 30)
    # PoseArray is not a default topic: --topics asks for it.
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 0, "--wait-for-subscribers", 1, "--publish-every", every,
                                     "--duration", duration, "--topics", "body_states,poses"), env=env)
    exited_ok(ctx, node, 60)
    exited_ok(ctx, sub, 60, "Python subscriber")
    states, poses = [], []
    with open(out) as f:
        for line in f:
            m = json.loads(line)
            (states if m["topic"] == "body_states" else poses).append(m)
    ctx.check([m["step"] for m in states] == steps, f"body states: steps {[m['step'] for m in states][:5]}... "
                                                    f"({len(states)}), want 0, {every}, ..., 2000")
    ctx.check(len(poses) == len(steps), f"poses: {len(poses)} messages, want {len(steps)}")
    dt = 0.001
    bad = 0
    for k, step in enumerate(steps):
        body_rows = rows[step]
        t_ns = int(math.floor(float(body_rows[0][col["t"]]) * 1e9 + 0.5))
        stamp = [t_ns // 10**9, t_ns % 10**9]
        for m in ([states[k]] if k < len(states) else []) + ([poses[k]] if k < len(poses) else []):
            if [m["sec"], m["nanosec"]] != stamp or m["frame_id"] != "world":
                bad += 1
                ctx.check(False, f"{m['topic']} step {step}: stamp {m['sec']}.{m['nanosec']:09d} "
                                 f"frame {m['frame_id']!r}, want {stamp} 'world'")
        if k < len(states):
            got = states[k]["bodies"]
            want = [[int(r[col["body"]])] + [float(r[col[q]]) for q in ("x", "y", "theta", "vx", "vy", "omega")]
                    for r in body_rows]
            got = [[b[0]] + [float(v) for v in b[1:]] for b in got]
            if got != want:
                bad += 1
                ctx.check(False, f"body states step {step}: {got} != CSV {want}")
        if k < len(poses):
            want = []
            for r in body_rows:
                th = float(r[col["theta"]])
                want.append([float(r[col["x"]]), float(r[col["y"]]), 0.0, 0.0, 0.0, math.sin(0.5 * th),
                             math.cos(0.5 * th)])
            got = [[float(v) for v in p] for p in poses[k]["poses"]]
            if got != want:
                bad += 1
                ctx.check(False, f"poses step {step}: {got} != {want}")
        if bad > 10:
            break
    if bad == 0:
        ctx.log(f"Python cyclonedds subscriber: {len(states)} BodyStates and {len(poses)} PoseArray of "
                f"{len(rows[0])} bodies equal to rbsim run --csv, bit for bit")


# --- network namespaces ----------------------------------------------------------------------

NETNS_PREFIX = "rbsim-e2e-"


def ip(ctx, *args, check=True):
    r = subprocess.run(["ip", *args], capture_output=True, text=True, timeout=20)
    if check and r.returncode != 0:
        raise Failure(f"ip {' '.join(args)}: {r.stderr.strip()}")
    return r


def sweep_stale_netns(ctx):
    r = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True, timeout=20)
    for line in r.stdout.splitlines():
        name = line.split()[0] if line.split() else ""
        if not name.startswith(NETNS_PREFIX):
            continue
        try:
            pid = int(name[len(NETNS_PREFIX):].split("-")[0])
        except ValueError:
            continue
        if pid != os.getpid() and not os.path.exists(f"/proc/{pid}"):
            ctx.log(f"removing stale namespace {name} of a dead run")
            subprocess.run(["ip", "netns", "del", name], capture_output=True, timeout=20)


def netns_config(address, peer):
    # A short lease and SPDP interval: a peer behind a link that went down is dropped after 2 s
    # and found again within a second of the link coming back (the defaults are 10 s and 30 s).
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<CycloneDDS xmlns="https://cdds.io/config">
  <Domain Id="any">
    <General>
      <Interfaces>
        <NetworkInterface address="{address}"/>
      </Interfaces>
      <AllowMulticast>false</AllowMulticast>
    </General>
    <Discovery>
      <LeaseDuration>2 s</LeaseDuration>
      <SPDPInterval>0.5 s</SPDPInterval>
      <ParticipantIndex>auto</ParticipantIndex>
      <MaxAutoParticipantIndex>20</MaxAutoParticipantIndex>
      <Peers>
        <Peer Address="{address}"/>
        <Peer Address="{peer}"/>
      </Peers>
    </Discovery>
  </Domain>
</CycloneDDS>
"""


class TwoHosts:
    """Two network namespaces a and b joined by a veth pair (10.231.0.1 <-> 10.231.0.2), each
    with a Cyclone configuration for its side; deleted on exit. `skip` holds the reason when
    namespaces are not permitted here."""

    def __init__(self, ctx):
        self.ctx, self.skip, self.created = ctx, None, []
        self.a, self.b = f"{NETNS_PREFIX}{ctx.pid}-a", f"{NETNS_PREFIX}{ctx.pid}-b"
        self.va, self.vb = f"rbe{ctx.pid % 100000}a", f"rbe{ctx.pid % 100000}b"

    def __enter__(self):
        ctx = self.ctx
        if shutil.which("ip") is None:
            self.skip = "the 'ip' command (iproute2) is not installed: no network namespaces"
            return self
        sweep_stale_netns(ctx)
        r = ip(ctx, "netns", "add", self.a, check=False)
        if r.returncode != 0:
            self.skip = f"network namespaces are not permitted here (ip netns add: {r.stderr.strip()})"
            return self
        self.created.append(self.a)
        ip(ctx, "netns", "add", self.b)
        self.created.append(self.b)
        # The veth pair is created inside namespace a (never in the host's), one end moved to b.
        r = ip(ctx, "-n", self.a, "link", "add", self.va, "type", "veth", "peer", "name", self.vb, "netns", self.b,
               check=False)
        if r.returncode != 0:
            self.skip = f"cannot create a veth pair between network namespaces here ({r.stderr.strip()})"
            return self
        for ns, dev, addr in ((self.a, self.va, "10.231.0.1/24"), (self.b, self.vb, "10.231.0.2/24")):
            ip(ctx, "-n", ns, "addr", "add", addr, "dev", dev)
            ip(ctx, "-n", ns, "link", "set", dev, "up")
            ip(ctx, "-n", ns, "link", "set", "lo", "up")
        self.cfg_a, self.cfg_b = ctx.path("cyclonedds-a.xml"), ctx.path("cyclonedds-b.xml")
        with open(self.cfg_a, "w") as f:
            f.write(netns_config("10.231.0.1", "10.231.0.2"))
        with open(self.cfg_b, "w") as f:
            f.write(netns_config("10.231.0.2", "10.231.0.1"))
        return self

    def __exit__(self, *exc):
        for ns in self.created:
            subprocess.run(["ip", "netns", "del", ns], capture_output=True, timeout=20)
        left = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True, timeout=20).stdout
        self.ctx.check(self.a not in left and self.b not in left, f"namespaces left behind: {left}")
        return False

    def rb(self, name, side, *args, extra_env=None):
        """Starts rbsim in namespace `side` ("a" or "b") with that side's configuration."""
        ns, cfg = (self.a, self.cfg_a) if side == "a" else (self.b, self.cfg_b)
        return self.ctx.start(name, ["ip", "netns", "exec", ns, self.ctx.rbsim, *map(str, args)],
                              env={**self.ctx.env(uri="file://" + cfg), **(extra_env or {})})

    def rx_bytes(self):
        r = ip(self.ctx, "-n", self.b, "-s", "-j", "link", "show", "dev", self.vb)
        return json.loads(r.stdout)[0]["stats64"]["rx"]["bytes"]

    def link(self, up):
        ip(self.ctx, "-n", self.a, "link", "set", self.va, "up" if up else "down")
        self.ctx.log(f"link {self.va} {'up' if up else 'down'}")


def case_netns(ctx):
    """Node and recorder on two hosts: network namespaces joined by a veth pair, nothing lost."""
    with TwoHosts(ctx) as net:
        if net.skip:
            print(f"SKIP: {net.skip}")
            return SKIP
        rx0 = net.rx_bytes()
        scene = ctx.scene("airplane.xml")
        every = 100
        run = ctx.path("run.mcap")
        ctx.rbrun("run-record", "run", scene, "--record", run, "--record-every", every, "--namespace", ctx.ns)
        want = Log(run)
        n = len(want.messages)
        out = ctx.path("remote.mcap")
        rec = net.rb("record-in-b", "b", *record_args(ctx, out, "--max-messages", n, "--wall-duration", 90))
        node = net.rb("node-in-a", "a", *node_args(ctx, scene, "--rate", 0, "--publish-every", every,
                                                   "--wait-for-subscribers", 1))
        exited_ok(ctx, node, 90, "node in namespace a")
        exited_ok(ctx, rec, 90, "recorder in namespace b")
        ctx.check(counts_line(rec) == (n, 0), f"remote recorder counts {counts_line(rec)}, want ({n}, 0)")
        got = Log(out)
        expect_indexed(ctx, got, n)
        same_payloads(ctx, got, want, "recording across the veth pair vs rbsim run --record")
        payload = sum(len(m[5]) for m in got.messages)
        rx = net.rx_bytes() - rx0
        ctx.check(rx > payload, f"veth {net.vb} received {rx} bytes, less than the {payload} payload bytes recorded")
        ctx.log(f"veth {net.vb} (namespace b) received {rx} bytes for {payload} payload bytes")
    return 0


def case_security(ctx):
    """DDS Security on two hosts (network namespaces): keystore and enclaves made by `rbsim security`;
    a secured node in a and a secured recorder in b lose nothing and record what `rbsim run --record`
    records; an unsecured recorder and one whose identity comes from another keystore's CA receive
    nothing; an enclave whose permissions omit a topic cannot read it; a tampered permissions file is
    refused, naming it."""
    with TwoHosts(ctx) as net:
        if net.skip:
            print(f"SKIP: {net.skip}")
            return SKIP
        domain = 17  # inside the namespaces only: no other case is there, and security needs <= 230
        ks, other = ctx.path("keystore"), ctx.path("other-keystore")
        ctx.rbrun("keystore", "security", "create-keystore", ks)
        ctx.rbrun("enclave-node", "security", "create-enclave", ks, "/" + ctx.ns, "--namespace", ctx.ns)
        ctx.rbrun("enclave-recorder", "security", "create-enclave", ks, "/rbsim_recorder", "--namespace", ctx.ns)
        ctx.rbrun("enclave-restricted", "security", "create-enclave", ks, "/restricted", "--namespace", ctx.ns,
                  "--topics", "scene,markers")
        ctx.rbrun("keystore-other", "security", "create-keystore", other)
        ctx.rbrun("enclave-other", "security", "create-enclave", other, "/rbsim_recorder", "--namespace", ctx.ns)
        tampered = os.path.join(ks, "enclaves", "tampered")
        shutil.copytree(os.path.join(ks, "enclaves", "rbsim_recorder"), tampered, symlinks=True)
        p7s = os.path.join(tampered, "permissions.p7s")
        with open(p7s) as f:
            text = f.read()
        with open(p7s, "w") as f:
            f.write(text.replace("<default>DENY</default>", "<default>ALLOW</default"))
        secured = {"ROS_SECURITY_ENABLE": "true", "ROS_SECURITY_STRATEGY": "Enforce", "ROS_SECURITY_KEYSTORE": ks}

        scene, every = ctx.scene("airplane.xml"), 100
        run = ctx.path("run.mcap")
        # 3 s of real time: long enough for the outsiders to have discovered an unsecured node.
        ctx.rbrun("run-record", "run", scene, "--duration", 3, "--record", run, "--record-every", every,
                  "--namespace", ctx.ns)
        want = Log(run)
        n = len(want.messages)
        out, plain, foreign = ctx.path("secured.mcap"), ctx.path("plain.mcap"), ctx.path("foreign.mcap")
        rec = net.rb("record-secured", "b", *record_args(ctx, out, "--max-messages", n, "--wall-duration", 90,
                                                         domain=domain), extra_env=secured)
        outsider = net.rb("record-unsecured", "b", *record_args(ctx, plain, "--wall-duration", 6, domain=domain))
        stranger = net.rb("record-other-ca", "b", *record_args(ctx, foreign, "--wall-duration", 6, domain=domain),
                          extra_env={**secured, "ROS_SECURITY_KEYSTORE": other})
        node = net.rb("node-secured", "a", *node_args(ctx, scene, "--duration", 3, "--rate", 1, "--publish-every", every,
                                                      "--wait-for-subscribers", 1, domain=domain),
                      extra_env=secured)
        exited_ok(ctx, node, 90, "secured node in namespace a")
        exited_ok(ctx, rec, 90, "secured recorder in namespace b")
        ctx.check(f"secured as enclave /{ctx.ns} (Enforce)" in node.stderr(),
                  f"the node does not say it runs secured:\n{node.stderr()}")
        ctx.check("secured as enclave /rbsim_recorder (Enforce)" in rec.stderr(),
                  f"the recorder does not say it runs secured:\n{rec.stderr()}")
        ctx.check(counts_line(rec) == (n, 0), f"secured recorder counts {counts_line(rec)}, want ({n}, 0)")
        got = Log(out)
        expect_indexed(ctx, got, n)
        same_payloads(ctx, got, want, "secured recording across the veth pair vs rbsim run --record")
        rc, _, err = ctx.rbrun("check-secured", "check", out, run, "--ignore-log-time", ok=False)
        ctx.check(rc == 0, f"rbsim check of the secured recording: exit {rc}\n{err}")
        for proc, what in ((outsider, "an unsecured recorder"), (stranger, "a recorder of another CA")):
            rc = proc.wait(60)
            ctx.check(rc == 1 and "nothing received" in proc.stderr(),
                      f"{what} exited {rc}, want 1 having received nothing:\n{proc.output()}")
        for path in (plain, foreign):
            ctx.check(not os.path.exists(path), f"{path} was written by a recorder that should see nothing")

        narrow = net.rb("record-restricted", "b", *record_args(ctx, ctx.path("narrow.mcap"), "--wall-duration", 5,
                                                               domain=domain),
                        extra_env={**secured, "ROS_SECURITY_ENCLAVE_OVERRIDE": "/restricted"})
        rc = narrow.wait(60)
        ctx.check(rc == 1 and "Not Allowed By Security" in narrow.stderr(),
                  f"an enclave without body_states exited {rc}, want 1 refused by security:\n{narrow.output()}")
        bad = net.rb("record-tampered", "b", *record_args(ctx, ctx.path("tampered.mcap"), "--wall-duration", 5,
                                                          domain=domain),
                     extra_env={**secured, "ROS_SECURITY_ENCLAVE_OVERRIDE": "/tampered"})
        rc = bad.wait(60)
        ctx.check(rc == 1 and f"{p7s}: its signature does not verify" in bad.stderr(),
                  f"a tampered permissions file: exit {rc}, want 1 naming it:\n{bad.output()}")
    return 0


def case_netns_link_flap(ctx):
    """A two-host recording whose link goes down twice: for 1 s (under the 2 s DDS lease: reliable
    retransmission, nothing lost) and for 4 s (the node drops the unreachable reader and
    messages are lost). The recorder carries on, finds the node again, and reports exactly the
    number of messages missing from its file; what it has equals the run's bytes."""
    with TwoHosts(ctx) as net:
        if net.skip:
            print(f"SKIP: {net.skip}")
            return SKIP
        scene = ctx.scene("cantilever.xml")
        every, duration = 50, 14
        run = ctx.path("run.mcap")
        ctx.rbrun("run-record", "run", scene, "--duration", duration, "--record", run, "--record-every", every,
                  "--namespace", ctx.ns)
        want = Log(run)
        out = ctx.path("remote.mcap")
        rec = net.rb("record-in-b", "b", *record_args(ctx, out, "--wall-duration", 120))
        node = net.rb("node-in-a", "a", *node_args(ctx, scene, "--rate", 1, "--publish-every", every,
                                                   "--duration", duration, "--wait-for-subscribers", 1))
        node.wait_for_text("rbsim node:", 30, stream="stderr")
        t0 = time.monotonic()

        def at(seconds):
            time.sleep(max(0.0, t0 + seconds - time.monotonic()))

        at(2.0)
        net.link(False)
        at(3.0)
        net.link(True)
        at(6.0)
        net.link(False)
        at(10.0)
        net.link(True)
        exited_ok(ctx, node, 60, "node in namespace a")
        # Settle: reliable retransmissions of the last messages reach the recorder.
        time.sleep(1.5)
        rec.signal(signal.SIGINT)
        exited_ok(ctx, rec, 30, "recorder in namespace b (SIGINT)")
        got = Log(out)
        expect_indexed(ctx, got)
        counts = counts_line(rec)
        ctx.require(counts is not None, f"no counts line from the recorder:\n{rec.stderr()}")
        received, reported_lost = counts
        # The transient-local scene description and markers are sent again each time the node finds
        # the recorder again: compare them once.
        got_by, want_by = got.by_suffix(), want.by_suffix()
        for latched in LATCHED:
            again = got_by.get(latched, [])
            ctx.check(len(again) >= 1 and all(p == want_by[latched][0] for p in again),
                      f"{len(again)} {latched} messages recorded, or one differs from the run's")
        missing, extra = 0, 0
        for suffix, payloads in want_by.items():
            if suffix in LATCHED:
                continue
            have = got_by.get(suffix, [])
            want_steps = {sim_stamp(suffix, p): p for p in payloads}
            have_steps = {sim_stamp(suffix, p): p for p in have}
            extra += sum(1 for s, p in have_steps.items() if want_steps.get(s) != p) + len(have) - len(have_steps)
            missing += sum(1 for s in want_steps if s not in have_steps)
        ctx.check(extra == 0, f"{extra} recorded messages are not the run's (or duplicated)")
        ctx.check(missing > 0, "nothing was lost during a 4 s outage with a 2 s lease: the outage did not happen?")
        ctx.check(reported_lost == missing, f"recorder reports {reported_lost} lost, {missing} are missing")
        last = max(stamp_of(p) for p in got_by.get("body_states", [b"\0" * 16]))
        ctx.check(last == max(stamp_of(p) for p in want_by["body_states"]),
                  f"the recording stops at stamp {last}: the recorder did not carry on to the end")
        ctx.log(f"link flaps: {received} received, {missing} missing, recorder reported {reported_lost} lost")
    return 0


def case_ros_graph(ctx):
    """rbsim node on the ROS 2 graph as an independent observer (Python cyclonedds, graph_peer.py)
    sees it: the ros_discovery_info entry names the node and lists the GIDs of exactly the
    endpoints DDS discovery reports for its participant (but the entry's own writer), 16 bytes on
    Jazzy and 24 (zero-padded) with ROS_DISTRO=humble; USER_DATA enclave=/; and the start line on
    /rosout at simulated time 0."""
    env = ctx.env(uri="file://" + ctx.loopback_xml)
    peer = os.path.join(os.path.dirname(__file__), "graph_peer.py")
    for distro, gid_size in ((None, 16), ("humble", 24)):
        run_env = dict(env)
        run_env.pop("ROS_DISTRO", None)
        if distro:
            run_env["ROS_DISTRO"] = distro
        tag = distro or "jazzy"
        node = ctx.rb(f"node-{tag}", "node", ctx.scene("chain.xml"), "--domain", ctx.domain, "--namespace",
                      f"{ctx.ns}/sim", "--loop", env=run_env)
        rc, out, err = ctx.run(f"peer-{tag}", [sys.executable, peer, "--domain", str(ctx.domain), "--name", "sim",
                                               "--gid-size", str(gid_size), "--timeout", "30"], timeout=60, env=env)
        node.signal(signal.SIGINT)
        exited_ok(ctx, node, 30)
        if not ctx.check(rc == 0, f"{tag}: graph peer exited with {rc}\n{out}{err}"):
            continue
        got = json.loads(out.strip().splitlines()[-1])
        entry, log = got["entry"], got["log"]
        ctx.check(entry["namespace"] == "/" + ctx.ns, f"{tag}: namespace {entry['namespace']!r}")
        gids = entry["writers"] + entry["readers"] + [entry["participant"]]
        ctx.check(all(len(g) == 2 * gid_size and g[32:] == "0" * (2 * gid_size - 32) for g in gids),
                  f"{tag}: GIDs not {gid_size} bytes of GUID and zeros: {gids}")
        listed = sorted(g[:32] for g in entry["writers"])
        discovered = sorted(k for k, topic in got["writers"].items() if topic != "ros_discovery_info")
        ctx.check(listed == discovered and len(listed) >= 8,
                  f"{tag}: writers listed {listed} != discovered {got['writers']}")
        ctx.check(sorted(g[:32] for g in entry["readers"]) == sorted(got["readers"]),
                  f"{tag}: readers listed {entry['readers']} != discovered {got['readers']}")
        ctx.check(got["user_data"] == "enclave=/;", f"{tag}: participant USER_DATA {got['user_data']!r}")
        ctx.check(log["level"] == 20 and log["name"] == f"{ctx.ns}.sim" and log["msg"].startswith("rbsim node: ")
                  and log["sec"] == 0, f"{tag}: /rosout start line {log}")
        ctx.log(f"{tag}: node /{ctx.ns}/sim with {len(listed)} writers, GIDs of {gid_size} bytes, "
                f"USER_DATA {got['user_data']!r}, /rosout {log['name']}: {log['msg'][:40]}...")


def case_type_description(ctx):
    """rbsim node's ~/get_type_description as an independent client (Python cyclonedds,
    type_description_client.py) calls it: asked for the hash the node's body_states writer
    announces in its USER_DATA, it answers that type's description, whose REP 2011 hash computed in
    Python is the announced one, with the .msg texts as sources; a hash no type has fails in rcl's
    words; started with -p start_type_description_service:=false, the service is not there."""
    env = ctx.env(uri="file://" + ctx.loopback_xml)
    client = os.path.join(os.path.dirname(__file__), "type_description_client.py")
    node_name, topic, type_name = f"/{ctx.ns}", f"/{ctx.ns}/body_states", "rbsim_msgs/msg/BodyStates"
    args = [sys.executable, client, "--domain", str(ctx.domain), "--node", node_name, "--topic", topic,
            "--type", type_name]
    node = ctx.rb("node", "node", ctx.scene("chain.xml"), "--domain", ctx.domain, "--namespace", ctx.ns, "--loop",
                  env=env)
    rc, out, err = ctx.run("client", args + ["--timeout", "40"], timeout=90, env=env)
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 30)
    if ctx.check(rc == 0, f"type description client exited with {rc}\n{out}{err}"):
        got = json.loads(out.strip().splitlines()[-1])
        with open(os.path.join(ctx.src, "tools", "msgs", "definitions", "rbsim_msgs", "msg",
                               "BodyStates.msg"), encoding="utf-8") as f:
            text = f.read()
        ctx.check(got["announced"] and got["announced"].startswith("RIHS01_"), f"announced hash {got['announced']!r}")
        ctx.check(got["successful"] and got["failure_reason"] == "", f"reply {got['successful']} {got['failure_reason']!r}")
        ctx.check(got["type_name"] == type_name, f"described {got['type_name']!r}")
        ctx.check(got["description_hash"] == got["announced"],
                  f"the description hashes to {got['description_hash']}, the writer announces {got['announced']}")
        ctx.check(got["sources"] and got["sources"][0] == [type_name, "msg", text.rstrip("\n")],
                  f"first source {got['sources'][:1]}")
        ctx.check([s[0] for s in got["sources"][1:]] == got["referenced"],
                  f"sources {[s[0] for s in got['sources']]} for referenced {got['referenced']}")
        ctx.check(got["unknown"] == [False, "Type not currently in use by this node"], f"unknown hash: {got['unknown']}")
        ctx.log(f"{type_name}: {got['announced']} described ({len(got['referenced'])} referenced types, "
                f"{len(got['sources'])} sources)")
    node = ctx.rb("node-off", "node", ctx.scene("chain.xml"), "--domain", ctx.domain, "--namespace", ctx.ns, "--loop",
                  "--ros-args", "-p", "start_type_description_service:=false", env=env)
    rc, out, err = ctx.run("client-off", args + ["--timeout", "40", "--expect-none"], timeout=90, env=env)
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 30)
    if ctx.check(rc == 0, f"type description client (off) exited with {rc}\n{out}{err}"):
        ctx.check(json.loads(out.strip().splitlines()[-1]) == {"node_seen": True, "matched": False},
                  f"start_type_description_service:=false still serves: {out}")


def case_ros_env(ctx):
    """ROS 2's environment variables, on loopback only: ROS_DOMAIN_ID alone puts a node and a
    recorder on the same domain (the recorder gets everything), --domain wins over it, a recorder
    on domain 0 or with ROS_AUTOMATIC_DISCOVERY_RANGE=OFF gets nothing; invalid values are
    one-line errors naming the variable."""
    scene = ctx.scene("cantilever.xml")
    every = 10
    run = ctx.path("run.mcap")
    ctx.rbrun("run-record", "run", scene, "--record", run, "--record-every", every, "--namespace", ctx.ns)
    want = Log(run)
    steps = max(step_of(p) for p in want.by_suffix()["body_states"])
    expected = len(LATCHED) + len(PER_STEP) * (steps // every + 1)
    d = str(ctx.domain)
    on_d = dict(ctx.env(), ROS_DOMAIN_ID=d)
    # No --domain: ROS_DOMAIN_ID decides.
    rec_env = ctx.rb("record-env", "record", ctx.path("env.mcap"), "--namespace", ctx.ns,
                     "--max-messages", expected, "--wall-duration", 60, env=on_d)
    # --domain wins over ROS_DOMAIN_ID; LOCALHOST with a static peer on this host.
    rec_flag = ctx.rb("record-flag", "record", ctx.path("flag.mcap"), "--domain", d, "--namespace", ctx.ns,
                      "--max-messages", expected, "--wall-duration", 60,
                      env=dict(ctx.env(), ROS_DOMAIN_ID="0", ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
                               ROS_STATIC_PEERS="localhost"))
    # Must see nothing: domain 0 (nothing set), and the node's domain with discovery OFF.
    rec_zero = ctx.rb("record-zero", "record", ctx.path("zero.mcap"), "--namespace", ctx.ns, "--wall-duration", 60)
    rec_off = ctx.rb("record-off", "record", ctx.path("off.mcap"), "--namespace", ctx.ns, "--wall-duration", 60,
                     env=dict(on_d, ROS_AUTOMATIC_DISCOVERY_RANGE="OFF"))
    for p in (rec_env, rec_flag, rec_zero, rec_off):
        p.wait_for_text("rbsim record: recording", 20, stream="stderr")
    node = ctx.rb("node-env", "node", scene, "--namespace", ctx.ns, "--rate", 0, "--publish-every", every,
                  "--wait-for-subscribers", 2, env=on_d)
    exited_ok(ctx, node, 70)
    exited_ok(ctx, rec_env, 70)
    exited_ok(ctx, rec_flag, 70)
    time.sleep(1.0)  # what the others would have received by now had they matched
    for p in (rec_zero, rec_off):
        p.signal(signal.SIGINT)
        p.wait(30)
    ctx.check(f"on domain {d} (" in node.stderr(), f"the node does not say it runs on domain {d}:\n{node.stderr()}")
    ctx.check(f"on domain {d} (LOCALHOST)" in rec_env.stderr(),
              f"record-env does not say domain {d} (LOCALHOST):\n{rec_env.stderr()}")
    ctx.check(f"on domain {d} (LOCALHOST, static peers localhost)" in rec_flag.stderr(),
              f"record-flag does not say domain {d} with its static peer:\n{rec_flag.stderr()}")
    ctx.check("on domain 0 (LOCALHOST)" in rec_zero.stderr(), f"record-zero is not on domain 0:\n{rec_zero.stderr()}")
    ctx.check(f"on domain {d} (OFF)" in rec_off.stderr(), f"record-off is not OFF:\n{rec_off.stderr()}")
    for p, name in ((rec_env, "env.mcap"), (rec_flag, "flag.mcap")):
        ctx.check(counts_line(p) == (expected, 0),
                  f"{p.name} reports {counts_line(p)} (received, lost), want ({expected}, 0)\n{p.output()}")
        same_payloads(ctx, Log(ctx.path(name)), want, f"{name} vs rbsim run --record")
    for p, name in ((rec_zero, "zero.mcap"), (rec_off, "off.mcap")):
        got = counts_line(p)
        if got is None and os.path.exists(ctx.path(name)):
            got = (len(Log(ctx.path(name)).messages), 0)
        ctx.check(got in (None, (0, 0)), f"{p.name} received {got} (received, lost), want nothing\n{p.output()}")
        # A recorder that received nothing says so, exits 1 and leaves no file.
        ctx.check(p.rc == 1 and "nothing received" in p.stderr() and not os.path.exists(ctx.path(name)),
                  f"{p.name}: want exit 1, 'nothing received' and no {name}\n{p.output()}")

    # Invalid values: an error exit and one line naming the variable, before any DDS traffic.
    x = ctx.path("run.mcap")
    bad = [
        ("record", ("record", ctx.path("bad1.mcap")), {"ROS_DOMAIN_ID": "abc"},
         "ROS_DOMAIN_ID='abc' is not a DDS domain id"),
        ("node", ("node", scene), {"ROS_DOMAIN_ID": "233"}, "ROS_DOMAIN_ID='233': domain id 233 out of range"),
        ("replay", ("replay", x), {"ROS_AUTOMATIC_DISCOVERY_RANGE": "EVERYWHERE"},
         "ROS_AUTOMATIC_DISCOVERY_RANGE='EVERYWHERE' is not a discovery range"),
        ("node", ("node", scene, "--domain", d), {"ROS_LOCALHOST_ONLY": "yes"}, "ROS_LOCALHOST_ONLY='yes'"),
        ("record", ("record", ctx.path("bad2.mcap"), "--domain", d), {"ROS_STATIC_PEERS": "a b"},
         "ROS_STATIC_PEERS: 'a b' is not a host name"),
    ]
    for i, (cmd, args, extra, text) in enumerate(bad):
        rc, out, err = ctx.rbrun(f"bad-env-{i}", *args, env=dict(ctx.env(), **extra), ok=False, timeout=30)
        lines = err.strip().splitlines()
        ctx.check(rc == 1, f"{extra}: exit {rc}, want 1\n{out}{err}")
        ctx.check(len(lines) == 1 and lines[0].startswith(f"rbsim {cmd}: error: ") and text in lines[0],
                  f"{extra}: want one line 'rbsim {cmd}: error: ...{text}...', got:\n{err}")
    # --domain wins over an invalid ROS_DOMAIN_ID too (rcl reads it only when no domain is given).
    rc, out, err = ctx.rbrun("domain-wins", "replay", x, "--domain", d, "--rate", 0, "-q",
                             env=dict(ctx.env(), ROS_DOMAIN_ID="abc"), ok=False, timeout=30)
    ctx.check(rc == 0, f"replay --domain {d} with ROS_DOMAIN_ID=abc: exit {rc}\n{out}{err}")


# --- bad input and faults --------------------------------------------------------------------


def case_bad_input(ctx):
    """Clear errors and a nonzero exit for bad names, files, domains and configurations."""
    x = ctx.path("run.mcap")
    ctx.rbrun("run-record", "run", ctx.scene("airplane.xml"), "--duration", 0.1, "--record", x)
    garbage = ctx.path("garbage.mcap")
    with open(garbage, "wb") as f:
        f.write(os.urandom(4096))
    empty = ctx.path("empty.mcap")
    open(empty, "wb").close()
    truncated = ctx.path("truncated.mcap")
    with open(x, "rb") as f:
        data = f.read()
    with open(truncated, "wb") as f:
        f.write(data[:len(data) // 2])
    from mcap.writer import Writer

    def one_message_log(name, schema_name, schema, topic, data):
        """A ros2-profile MCAP file (official writer) holding one message."""
        path = ctx.path(name)
        with open(path, "wb") as f:
            w = Writer(f)
            w.start(profile="ros2", library="e2e")
            sid = w.register_schema(name=schema_name, encoding="ros2msg", data=schema)
            cid = w.register_channel(topic=topic, message_encoding="cdr", schema_id=sid)
            w.add_message(channel_id=cid, log_time=1, publish_time=1, data=data)
            w.finish()
        return path

    foreign = one_message_log("foreign.mcap", "std_msgs/msg/String", b"string data", "/chatter",
                              b"\x00\x01\x00\x00\x03\x00\x00\x00hi\x00\x00")
    # Our type name with another definition (e.g. an older rbsim): not replayed as ours.
    other_def = one_message_log("other-definition.mcap", "rbsim_msgs/msg/BodyStates", b"int32 something_else",
                                "/rbsim/body_states", b"\x00\x01\x00\x00\x07\x00\x00\x00")
    bad_xml = ctx.path("bad-config.xml")
    with open(bad_xml, "w") as f:
        f.write("<CycloneDDS><Domain><General><NoSuchSetting>1</NoSuchSetting></General></Domain></CycloneDDS>\n")
    # A stiff explicit-Euler spring that blows up (as in the command-line test of `rbsim run`).
    stiff = ctx.path("stiff.xml")
    with open(os.path.join(ctx.src, "test", "data", "fosssim", "scenes", "springtests", "test00ee.xml")) as f:
        text = f.read()
    with open(stiff, "w") as f:
        f.write(re.sub(r'k="[^"]*"', 'k="1e9"', text))
    scene = ctx.scene("airplane.xml")
    d = str(ctx.domain)
    cases = [
        ("node on a diverging scene", ("node", stiff, "--domain", d, "--rate", "0"), None, "step 64: body 0 T_point is not finite"),
        ("record unknown topic", ("record", ctx.path("o1.mcap"), "--domain", d, "--topics", "no_such_topic"), None,
         "unknown topic"),
        ("replay unknown topic", ("replay", x, "--domain", d, "--topics", "no_such_topic"), None, "unknown topic"),
        ("replay missing file", ("replay", ctx.path("missing.mcap"), "--domain", d), None, "cannot read"),
        ("replay garbage", ("replay", garbage, "--domain", d), None, "cannot read"),
        ("replay empty file", ("replay", empty, "--domain", d), None, "cannot read"),
        ("replay truncated file", ("replay", truncated, "--domain", d), None, "cannot read"),
        ("replay log without rbsim topics", ("replay", foreign, "--domain", d), None, "no rbsim topics"),
        ("replay log with another BodyStates definition", ("replay", other_def, "--domain", d), None,
         "differs from this build"),
        ("node domain 233", ("node", scene, "--domain", "233"), None, "out of range"),
        ("record domain 1000", ("record", ctx.path("o2.mcap"), "--domain", "1000"), None, "out of range"),
        ("replay domain 233", ("replay", x, "--domain", "233"), None, "out of range"),
        ("node missing CYCLONEDDS_URI file", ("node", scene, "--domain", d),
         "file://" + ctx.path("no-such-config.xml"), "CYCLONEDDS_URI"),
        ("record invalid CYCLONEDDS_URI", ("record", ctx.path("o3.mcap"), "--domain", d), "file://" + bad_xml,
         "CYCLONEDDS_URI"),
        ("replay invalid CYCLONEDDS_URI", ("replay", x, "--domain", d), "file://" + bad_xml, "CYCLONEDDS_URI"),
    ]
    for i, (what, args, uri, text) in enumerate(cases):
        rc, out, err = ctx.rbrun(f"bad-{i}", *args, env=ctx.env(uri=uri), ok=False, timeout=30)
        first = (err.strip().splitlines() or [""])[-1]
        ctx.check(rc != 0 and rc > 0, f"{what}: exit {rc}, want an error exit\n{out}{err}")
        ctx.check(text.lower() in err.lower(), f"{what}: stderr does not mention '{text}':\n{err}")
        ctx.log(f"{what}: exit {rc}: {first}")
    for name in ("o1.mcap", "o2.mcap"):
        ctx.check(not os.path.exists(ctx.path(name)) or os.path.getsize(ctx.path(name)) < 64 * 1024,
                  f"a failed record left a large {name}")


def case_record_disk_full(ctx):
    """A recorder whose writes fail (file-size limit, as a full disk) stops with an error, and
    the file is recoverable."""
    scene = ctx.scene("cantilever.xml")
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 2, "--publish-every", 2, "--loop"))
    node.wait_for_text("rbsim node:", 20, stream="stderr")
    out = ctx.path("full.mcap")
    limit = 3 * 1024 * 1024
    rec = ctx.rb("record-limited", *record_args(ctx, out, "--compression", "none", "--wall-duration", 60),
                 fsize_limit=limit)
    rc = rec.wait(60)
    ctx.check(rc != -signal.SIGXFSZ, "the recorder was killed by SIGXFSZ instead of stopping with an error")
    ctx.check(rc == 1, f"recorder past its file-size limit exited with {rc}, want 1\n{rec.output()}")
    ctx.check("file too large" in rec.stderr().lower() or "write" in rec.stderr().lower(),
              f"recorder error does not say the write failed:\n{rec.stderr()}")
    ctx.check(node.alive(), "the node stopped when the recorder failed")
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 15, "node stopped with SIGINT")
    size = os.path.getsize(out)
    ctx.check(size <= limit, f"{out}: {size} bytes, over the {limit}-byte limit")
    ctx.log(f"recorder stopped at {size} bytes: {(rec.stderr().strip().splitlines() or [''])[-1]}")
    check_recover(ctx, out, "recorder past its file-size limit")


# Mounts a file system that fails writes in one way at "$2", inside the mount namespace the test
# made, then runs the command after it and lists "$2". enospc: a 256 KiB tmpfs. edquot: a btrfs
# (on a loop device, its image on a scratch tmpfs) whose quota group allows 256 KiB. eio: an ext4
# mounted sync (each write reaches the device) whose loop device is then cut to 2 of its 16 MiB:
# every write beyond the end is an I/O error. Loop devices mounted with -o loop detach themselves
# when the namespace's mounts go. Exit 77: this machine cannot make that file system.
FAULTY_FS_SCRIPT = r"""
kind=$1 dir=$2; shift 2
scratch=$(mktemp -d) || exit 77
mount -t tmpfs -o size=200m rbsim-e2e-img "$scratch" || exit 77
case $kind in
enospc) mount -t tmpfs -o size=256k rbsim-e2e "$dir" || exit 77 ;;
edquot)
  { truncate -s 128M "$scratch/img" && mkfs.btrfs -q "$scratch/img" >/dev/null && mount -o loop "$scratch/img" "$dir" &&
    btrfs quota enable "$dir" && btrfs qgroup limit 256K "$dir"; } || exit 77 ;;
eio)
  { truncate -s 16M "$scratch/img" && mkfs.ext4 -q -O ^has_journal "$scratch/img" &&
    mount -o loop,sync,errors=continue "$scratch/img" "$dir" && rmdir "$dir/lost+found" &&
    dev=$(findmnt -n -o SOURCE "$dir") && truncate -s 2M "$scratch/img" && losetup -c "$dev"; } || exit 77 ;;
esac
"$@"; rc=$?; ls -A "$dir"; exit $rc
"""


def case_disk_full(ctx):
    """Write errors from real file systems, each mounted in a mount namespace the test creates: a
    full tmpfs (ENOSPC), a btrfs over its quota (EDQUOT) and an ext4 whose device fails writes
    (EIO). `rbsim run --csv` and `rbsim run --record` stop with one line naming the file, the bytes
    that reached it and the system's reason, exit 1, and nothing behind: the CSV was an unnamed
    temporary, and the run discards its unfinished recording (`rbsim record`'s is kept for
    `rbsim log recover`: record_disk_full). EFBIG (`ulimit -f`) is RunOutputs' unit test."""
    if shutil.which("unshare") is None:
        print("SKIP: no unshare (util-linux): no mount namespace")
        return SKIP
    scene = ctx.scene("cantilever.xml")
    faults = (("enospc", "No space left on device"), ("edquot", "Disk quota exceeded"),
              ("eio", "Input/output error"))
    made = []
    for kind, reason in faults:
        mnt = ctx.path(kind)
        os.makedirs(mnt, exist_ok=True)
        for what, out in (("csv", "out.csv"), ("record", "out.mcap")):
            path = os.path.join(mnt, out)
            extra = ("--compression", "none") if what == "record" else ()
            rc, listing, err = ctx.run(f"{kind}-{what}", ["unshare", "--mount", "--propagation", "private", "sh", "-c",
                                                         FAULTY_FS_SCRIPT, "faulty-fs", kind, mnt, ctx.rbsim, "run",
                                                         scene, "--steps", "20000", "-q", *extra, f"--{what}", path],
                                       timeout=120)
            if rc == 77:
                ctx.note(f"{kind}: this machine cannot make that file system here (not tested):\n{err}")
                break
            ctx.check(rc == 1, f"run --{what} on the {kind} file system exited {rc}, want 1:\n{err}")
            lines = [l for l in err.splitlines() if l.strip()]
            want = f"rbsim run: error: {path}: write failed after "
            ctx.check(len(lines) == 1 and lines[0].startswith(want) and lines[0].endswith(f" bytes: {reason}"),
                      f"run --{what} on {kind}: want one line \"{want}N bytes: {reason}\":\n{err}")
            ctx.check(listing.split() == [], f"run --{what} left {listing.split()} on the {kind} file system")
        else:
            made.append(kind)
    if "enospc" not in made:
        print("SKIP: cannot mount a tmpfs in a mount namespace here")
        return SKIP
    ctx.log(f"write errors tested on: {', '.join(made)}")
    return 0


def case_record_sigkill(ctx):
    """The recorder SIGKILLed at random moments (seeded; the seed is printed, RBSIM_E2E_SEED
    repeats a run): every message of every complete chunk in the killed file survives
    `rbsim log recover`, byte for byte, and the node carries on."""
    seed = int(os.environ.get("RBSIM_E2E_SEED", str(ctx.pid)))
    rng = random.Random(seed)
    ctx.log(f"seed {seed}")
    scene = ctx.scene("cantilever.xml")
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 4, "--publish-every", 4, "--loop"))
    node.wait_for_text("rbsim node:", 20, stream="stderr")
    for i in range(4):
        out = ctx.path(f"killed-{i}.mcap")
        rec = ctx.rb(f"record-{i}", *record_args(ctx, out, "--chunk-size", 32768, "--wall-duration", 60,
                                                 "--compression", ("zstd", "lz4", "none")[i % 3]))
        # Kill once the file has grown past its header, at a random moment within 0.2 .. 3 s.
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline and (not os.path.exists(out) or os.path.getsize(out) < 40000):
            time.sleep(0.05)
        time.sleep(rng.uniform(0.2, 3.0))
        rec.signal(signal.SIGKILL)
        rec.wait(10)
        ctx.check(rec.rc == -signal.SIGKILL, f"recorder {i} exited with {rec.rc}, not killed")
        ctx.log(f"recorder {i} killed at {os.path.getsize(out)} bytes")
        check_recover(ctx, out, f"recorder {i} killed")
    ctx.check(node.alive(), "the node stopped when its recorders were killed")
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 30, "node stopped with SIGINT")


def bag_metadata(path):
    """metadata.yaml of a bag directory, as a dict (rosbag2_bagfile_information)."""
    from ruamel.yaml import YAML  # rosbags' YAML library

    with open(os.path.join(path, "metadata.yaml")) as f:
        return YAML(typ="safe").load(f)["rosbag2_bagfile_information"]


def check_bag_with_rosbags(ctx, bag, what):
    """The `rosbags` library opens the bag, reads every message and agrees with metadata.yaml's
    counts; the official MCAP reader reads every file (CRCs checked). Returns the per-topic counts."""
    from pathlib import Path
    from rosbags.rosbag2 import Reader

    meta = bag_metadata(bag)
    files = [os.path.join(bag, f) for f in meta["relative_file_paths"]]
    with Reader(Path(bag)) as reader:
        counted = {}
        for connection, _, _ in reader.messages():
            counted[connection.topic] = counted.get(connection.topic, 0) + 1
        declared = {c.topic: c.msgcount for c in reader.connections}
        ctx.check(reader.message_count == sum(counted.values()),
                  f"{what}: rosbags read {sum(counted.values())} messages, metadata says {reader.message_count}")
    listed = {t["topic_metadata"]["name"]: t["message_count"] for t in meta["topics_with_message_count"]}
    ctx.check(counted == declared == listed, f"{what}: counts read {counted}, metadata {listed}")
    per_file = [len(Log(f).messages) for f in files]
    ctx.check(per_file == [f["message_count"] for f in meta["files"]],
              f"{what}: the files hold {per_file} messages, metadata says {[f['message_count'] for f in meta['files']]}")
    ctx.check(meta["version"] == 9 and meta["storage_identifier"] == "mcap" and meta["ros_distro"] == "jazzy",
              f"{what}: metadata version/storage/distro {meta['version']}/{meta['storage_identifier']}/{meta['ros_distro']}")
    return counted


def case_record_bag(ctx):
    """rbsim record DIR --max-file-size: a rosbag2 bag split into several files, each starting with
    the scene description and markers (each file checks and renders on its own); rosbags and the
    official MCAP reader agree with metadata.yaml; the bag read as one equals `rbsim run --record`."""
    scene = ctx.scene("cantilever.xml")
    duration = 3.0  # in real time: the topics interleave in each file as a node publishes them
    golden = ctx.path("golden.mcap")
    ctx.rbrun("golden", "run", scene, "--duration", duration, "--record", golden, "--namespace", ctx.ns)
    bag = ctx.path("bag")
    expected = len(Log(golden).messages)
    rec = ctx.rb("record", *record_args(ctx, bag, "--max-messages", expected, "--wall-duration", 90,
                                        "--chunk-size", 65536, "--max-file-size", 1048576))
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 1, "--duration", duration, "--wait-for-subscribers", 1))
    exited_ok(ctx, node, 90)
    exited_ok(ctx, rec, 90)
    meta = bag_metadata(bag)
    files = [os.path.join(bag, f) for f in meta["relative_file_paths"]]
    ctx.log(f"{len(files)} files: {meta['relative_file_paths']}")
    ctx.require(len(files) >= 3, f"--max-file-size 1048576 made {len(files)} files, want at least 3")
    ctx.check(files == [os.path.join(bag, f"bag_{i}.mcap") for i in range(len(files))],
              f"file names {meta['relative_file_paths']}")
    counted = check_bag_with_rosbags(ctx, bag, "split bag")
    # Each file starts with the latched topics, so the bag holds them once per file.
    for suffix in LATCHED:
        n = sum(v for k, v in counted.items() if k.endswith("/" + suffix))
        ctx.check(n == len(files), f"{suffix}: {n} messages in the bag, want one per file ({len(files)})")
    # Read as one recording: every message once, equal to the offline run.
    rbsim_check(ctx, bag, golden, "the bag against rbsim run --record", live=True)
    for i, f in enumerate(files):
        first = read_stream_messages(f)[0][0]
        ctx.check(first.endswith("/scene"), f"{f}: first message on {first}, want the scene description")
        ctx.rbrun(f"doctor-{i}", "log", "doctor", f, timeout=60)
    for i, f in ((0, files[0]), (len(files) - 1, files[-1])):  # the first and the last, each alone
        frames = ctx.path(f"frames-{i}")
        ctx.rbrun(f"render-{i}", "render", f, "--out", frames, "--fps", 2, timeout=120)
        ctx.check(len(os.listdir(frames)) > 0, f"{f} rendered no frame")
    rc, out, _ = ctx.rbrun("info", "log", "info", bag)
    ctx.check(f"rosbag2, {len(files)} files" in out, f"rbsim log info on the bag:\n{out}")


def case_record_bag_sigkill(ctx):
    """A split recorder SIGKILLed: metadata.yaml lists the closed files, each intact (the official
    reader, rosbags), the open one is saved by `rbsim log recover`, and the steps they hold follow
    on from each other with nothing lost between files."""
    scene = ctx.scene("cantilever.xml")
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 2, "--publish-every", 2, "--loop"))
    node.wait_for_text("rbsim node:", 20, stream="stderr")
    bag = ctx.path("killed")
    rec = ctx.rb("record", *record_args(ctx, bag, "--chunk-size", 16384, "--max-file-duration", 0.7,
                                        "--wall-duration", 60))
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and not os.path.exists(os.path.join(bag, "killed_3.mcap")):
        time.sleep(0.05)
    time.sleep(0.3)
    rec.signal(signal.SIGKILL)
    rec.wait(10)
    ctx.check(rec.rc == -signal.SIGKILL, f"recorder exited with {rec.rc}, not killed")
    meta = bag_metadata(bag)
    closed = [os.path.join(bag, f) for f in meta["relative_file_paths"]]
    present = sorted(os.path.join(bag, f) for f in os.listdir(bag) if f.endswith(".mcap"))
    ctx.require(len(closed) >= 3, f"metadata lists {len(closed)} closed files, want at least 3")
    open_files = [f for f in present if f not in closed]
    ctx.check(len(open_files) == 1, f"files not in metadata.yaml: {open_files}, want the one open file")
    check_bag_with_rosbags(ctx, bag, "killed bag (closed files)")
    recovered = check_recover(ctx, open_files[0], "the open file")
    # Steps per file: each file carries on from the last step of the one before (publish-every 2).
    logs = [Log(f) for f in closed] + ([recovered] if recovered else [])
    last = None
    for f, log in zip(closed + open_files, logs):
        steps = [step_of(m[5]) for m in log.messages if m[0].endswith("/body_states")]
        ctx.check(steps == sorted(steps) and all(b - a == 2 for a, b in zip(steps, steps[1:])),
                  f"{f}: body_states steps not every 2nd step: {steps[:5]}...")
        if last is not None and steps:
            ctx.check(steps[0] == last + 2 or steps[0] == 0, f"{f}: starts at step {steps[0]} after {last}: lost between files")
        if steps:
            last = steps[-1]
    ctx.check(node.alive(), "the node stopped when its recorder was killed")
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 30, "node stopped with SIGINT")


def case_record_snapshot(ctx):
    """rbsim record DIR --snapshot-duration 1: nothing written until asked; each snapshot (SIGUSR1) is
    a file of the bag holding exactly the last second of log time, contiguous steps, with the scene
    description and markers first, that renders on its own."""
    scene = ctx.scene("chain.xml")
    bag = ctx.path("snap")
    rec = ctx.rb("record", *record_args(ctx, bag, "--snapshot-duration", 1, "--wall-duration", 60))
    # An observer (a plain recorder, small chunks) shows how far the node got: a snapshot recorder
    # writes nothing until asked. The node waits for both.
    seen = ctx.path("observer.mcap")
    obs = ctx.rb("record-observer", *record_args(ctx, seen, "--chunk-size", 1024, "--wall-duration", 90,
                                                 "--node-name", "rbsim_observer"))
    # Long enough for both snapshots on a busy machine; stopped with SIGINT after them.
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 1, "--duration", 60, "--wait-for-subscribers", 2))
    # Its SIGUSR1 handler is in place once it says it records (before, SIGUSR1 would kill it).
    rec.wait_for_text("rbsim record: recording", 20, stream="stderr")
    # More than the second a snapshot keeps has gone out (not a time: discovery can take seconds).
    wait_recorded(ctx, obs, seen, lambda got: recorded_span(got) >= 1.3, 60, "1.3 s of body states")
    ctx.check(not any(f.endswith(".mcap") for f in os.listdir(bag)), "snapshot mode wrote a file before a snapshot")
    for i in range(2):
        if i > 0:  # a snapshot takes what it kept: 1.3 s more published since (seen by the observer)
            wait_recorded(ctx, obs, seen, lambda got: max((m[1] for m in got if m[0].endswith("/body_states")),
                                                          default=0) >= taken + 1_300_000_000,
                          60, "1.3 s of body states after the first snapshot")
        rec.signal(signal.SIGUSR1)
        rec.wait_for_text(f"written to {bag}/snap_{i}.mcap", 30, stream="stderr")
        taken = time.time_ns()
    ctx.require(node.alive(), f"the node ended before the snapshots were taken\n{node.output()}")
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 30)
    rec.signal(signal.SIGINT)
    exited_ok(ctx, rec, 30)
    obs.signal(signal.SIGINT)
    exited_ok(ctx, obs, 30, "the observing recorder")
    meta = bag_metadata(bag)
    ctx.check(meta["relative_file_paths"] == ["snap_0.mcap", "snap_1.mcap"], f"files {meta['relative_file_paths']}")
    check_bag_with_rosbags(ctx, bag, "snapshot bag")
    for i, f in enumerate(meta["relative_file_paths"]):
        log = Log(os.path.join(bag, f))
        ctx.check([m[0].rsplit("/", 1)[-1] for m in log.messages[:2]] == ["scene", "markers"] or
                  log.messages[0][0].endswith("/scene"), f"{f}: starts with {[m[0] for m in log.messages[:2]]}")
        per_step = [m for m in log.messages if m[0].endswith("/body_states")]
        steps = [step_of(m[5]) for m in per_step]
        span = (per_step[-1][2] - per_step[0][2]) / 1e9
        ctx.log(f"{f}: steps {steps[0]}..{steps[-1]} ({len(steps)}), log-time span {span:.3f} s")
        ctx.check(steps == list(range(steps[0], steps[0] + len(steps))), f"{f}: steps not contiguous")
        ctx.check(0.9 <= span <= 1.0, f"{f}: keeps {span:.3f} s of log time, want the last 1 s")
        ctx.rbrun(f"render-{i}", "render", os.path.join(bag, f), "--out", ctx.path(f"frames-{i}"), "--fps", 2)


def case_record_services(ctx):
    """rosbag2's recorder services on /rbsim_recorder, called by an independent Python cyclonedds
    client: pause holds (no steps recorded while paused, is_paused says so), resume goes on,
    split_bagfile starts a new file at once, snapshot outside snapshot mode fails; in snapshot mode
    the snapshot service writes the last second to the bag's next file."""
    from player_client import Player

    scene = ctx.scene("chain.xml")
    bag = ctx.path("bag")
    names = ("pause", "resume", "is_paused", "split_bagfile", "snapshot")
    rec = ctx.rb("record", *record_args(ctx, bag, "--wall-duration", 90, "--chunk-size", 1024))
    # Long enough for every call on a busy machine; stopped with SIGINT after them.
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 1, "--duration", 60, "--wait-for-subscribers", 1))
    client = Player(ctx.domain, "/rbsim_recorder", "file://" + ctx.loopback_xml, names=names)
    ctx.require(client.wait_matched(20), "the Python client did not match the recorder's five services in 20 s")

    def call(name):
        r = client.call(name)
        ctx.require(r is not None, f"no reply to {name}")
        return r
    # Steps recorded before the pause (not a time: discovery can take seconds).
    wait_recorded(ctx, rec, os.path.join(bag, "bag_0.mcap"), lambda got: per_topic(got).get("body_states", 0) >= 100,
                  60, "100 body states")
    call("pause")
    paused_at = time.time_ns()
    ctx.check(call("is_paused").paused, "is_paused false after pause")
    time.sleep(0.8)
    call("resume")
    resumed_at = time.time_ns()
    ctx.check(not call("is_paused").paused, "is_paused true after resume")
    call("split_bagfile")
    ctx.check(not call("snapshot").success, "snapshot succeeded outside snapshot mode")
    # Steps recorded after the split, in its new file.
    wait_recorded(ctx, rec, os.path.join(bag, "bag_1.mcap"), lambda got: per_topic(got).get("body_states", 0) >= 100,
                  60, "100 body states after the split")
    ctx.require(node.alive(), f"the node ended before the calls were done\n{node.output()}")
    node.signal(signal.SIGINT)
    exited_ok(ctx, node, 30)
    rec.signal(signal.SIGINT)
    exited_ok(ctx, rec, 30)
    meta = bag_metadata(bag)
    ctx.check(len(meta["relative_file_paths"]) == 2, f"split_bagfile made {meta['relative_file_paths']}, want 2 files")
    check_bag_with_rosbags(ctx, bag, "bag with a pause and a split")
    states = [m for f in meta["relative_file_paths"] for m in Log(os.path.join(bag, f)).messages
              if m[0].endswith("/body_states")]
    inside = [m for m in states if paused_at + 100_000_000 < m[2] < resumed_at - 100_000_000]
    ctx.check(not inside, f"{len(inside)} body states recorded while paused")
    steps = [step_of(m[5]) for m in states]
    gap = max(b - a for a, b in zip(steps, steps[1:]))
    ctx.log(f"largest step gap {gap} (the pause), {len(steps)} steps recorded")
    ctx.check(gap >= 500, f"the pause left a gap of {gap} steps, want >= 500 (0.8 s at 1 kHz)")

    # The same client (one participant per process) for the second recorder, once the first one's
    # endpoints are gone from it.
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(c["matches"]["w"] or c["matches"]["r"] for c in client.clients.values()):
        time.sleep(0.05)
    snap = ctx.path("snap")
    rec = ctx.rb("record-snap", *record_args(ctx, snap, "--snapshot-duration", 1, "--wall-duration", 60))
    seen = ctx.path("observer.mcap")  # how far the node got: the snapshot recorder writes nothing yet
    obs = ctx.rb("record-observer", *record_args(ctx, seen, "--chunk-size", 1024, "--wall-duration", 60,
                                                 "--node-name", "rbsim_observer"))
    node = ctx.rb("node-snap", *node_args(ctx, scene, "--rate", 1, "--duration", 3, "--wait-for-subscribers", 2))
    ctx.require(client.wait_matched(20), "no match with the snapshot recorder's services")
    wait_recorded(ctx, obs, seen, lambda got: recorded_span(got) >= 1.3, 60, "1.3 s of body states")
    ctx.check(call("snapshot").success, "snapshot failed in snapshot mode")
    exited_ok(ctx, node, 60)
    rec.signal(signal.SIGINT)
    exited_ok(ctx, rec, 30)
    obs.signal(signal.SIGINT)
    exited_ok(ctx, obs, 30, "the observing recorder")
    meta = bag_metadata(snap)
    ctx.check(meta["relative_file_paths"] == ["snap_0.mcap"], f"snapshot files {meta['relative_file_paths']}")
    states = [m for m in Log(os.path.join(snap, "snap_0.mcap")).messages if m[0].endswith("/body_states")]
    span = (states[-1][2] - states[0][2]) / 1e9
    ctx.check(0.9 <= span <= 1.0, f"the snapshot holds {span:.3f} s of log time, want the last 1 s")


def rss_kib(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def case_soak(ctx):
    """Node and recorder on a 1,000-body scene for --soak-seconds (real time): resident size of
    both flat after warm-up (growth < 5%), nothing lost, and the log passes `rbsim log doctor`
    and `rbsim check` against `rbsim run --record` of the same scene."""
    seconds = ctx.args.soak_seconds
    dt, every = 0.01, 5
    scene = ctx.path("grid1000.xml")
    with open(scene, "w") as f:
        subprocess.run([sys.executable, os.path.join(ctx.src, "bench", "make_grid_scene.py"), "1000", str(dt),
                        str(seconds)], stdout=f, check=True, timeout=60)
    steps = int(round(seconds / dt))
    published = steps // every + 1
    expected = len(LATCHED) + len(PER_STEP) * published
    live = ctx.path("live.mcap")
    rec = ctx.rb("record", *record_args(ctx, live, "--wall-duration", seconds + 120, "--max-messages", expected))
    node = ctx.rb("node", *node_args(ctx, scene, "--rate", 1, "--publish-every", every, "--wait-for-subscribers", 1))
    node.wait_for_text("rbsim node:", 60, stream="stderr")
    t0 = time.monotonic()
    warmup = max(5.0, 0.25 * seconds)
    samples = {"node": [], "record": []}  # (t, KiB)
    while node.alive() and time.monotonic() - t0 < seconds + 120:
        t = time.monotonic() - t0
        for name, proc in (("node", node), ("record", rec)):
            kib = rss_kib(proc.p.pid)
            if kib is not None:
                samples[name].append((t, kib))
        time.sleep(0.5)
    exited_ok(ctx, node, 60, "node")
    exited_ok(ctx, rec, 60, "recorder")
    wall = time.monotonic() - t0
    ctx.check(counts_line(rec) == (expected, 0),
              f"recorder reports {counts_line(rec)} (received, lost), want ({expected}, 0)\n{rec.stderr()}")
    for name, series in samples.items():
        after = [kib for t, kib in series if t >= warmup]
        if len(after) < 4:
            ctx.check(False, f"{name}: only {len(after)} resident-size samples after the {warmup:.0f} s warm-up")
            continue
        base, peak = after[0], max(after)
        growth = peak / base - 1.0
        ctx.log(f"{name}: resident size {base / 1024:.1f} MiB after warm-up, peak {peak / 1024:.1f} MiB "
                f"({100 * growth:+.2f}%), {len(series)} samples over {wall:.0f} s")
        if ctx.args.sanitized:
            ctx.note(f"{name}: AddressSanitizer build: resident size not judged (its quarantine grows by design)")
        else:
            ctx.check(growth < 0.05, f"{name}: resident size grew {100 * growth:.1f}% after warm-up "
                                     f"({base} -> {peak} KiB)")
    rc, out, err = ctx.rbrun("doctor", "log", "doctor", live, ok=False, timeout=300)
    ctx.check(rc == 0, f"rbsim log doctor on the soak log exited with {rc}\n{out}{err}")
    run = ctx.path("run.mcap")
    ctx.rbrun("run-record", "run", scene, "--record", run, "--record-every", every, "--namespace", ctx.ns, "-q",
              timeout=600)
    rbsim_check(ctx, live, run, "check-live-run", live=True)
    size = os.path.getsize(live)
    ctx.log(f"soak: {wall:.0f} s, {expected} messages, {size / 1e6:.1f} MB log, 0 lost")
    if not ctx.failures:
        for path in (live, run):
            os.remove(path)


# Every case, in the order of their CTest entries (an entry's --index is its place here).
CASES = {
    "node_record": case_node_record,
    "late_recorder": case_late_recorder,
    "replay_roundtrip": case_replay_roundtrip,
    "replay_options": case_replay_options,
    "subscribers_come_and_go": case_subscribers_come_and_go,
    "python_subscriber": case_python_subscriber,
    "netns": case_netns,
    "netns_link_flap": case_netns_link_flap,
    "bad_input": case_bad_input,
    "record_disk_full": case_record_disk_full,
    "record_sigkill": case_record_sigkill,
    "soak": case_soak,
    "ros_env": case_ros_env,
    "ros_graph": case_ros_graph,
    "record_bag": case_record_bag,
    "record_bag_sigkill": case_record_bag_sigkill,
    "record_snapshot": case_record_snapshot,
    "player": case_player,
    "record_services": case_record_services,
    "service_events": case_service_events,
    "security": case_security,
    "disk_full": case_disk_full,
    "type_description": case_type_description,
}


def add_case_arguments(ap):
    """The arguments every case's driver takes (this one's and startup_stops.py's)."""
    ap.add_argument("--index", type=int, required=True, help="test index (part of the DDS domain id)")
    ap.add_argument("--rbsim", required=True)
    ap.add_argument("--source-dir", required=True)
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--venv", required=True)
    ap.add_argument("--requirements", required=True)


def main():
    # The one list of cases: test/e2e/CMakeLists.txt reads it at configure time (one CTest entry
    # e2e.<case> each, --index its place in this list); --list needs no venv and no other option.
    if sys.argv[1:] == ["--list"]:
        print("\n".join(CASES))
        return 0
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--list", action="store_true", help="print the case names, one a line, and exit")
    ap.add_argument("--case", required=True, choices=sorted(CASES))
    add_case_arguments(ap)
    ap.add_argument("--soak-seconds", type=float, default=20.0, help="length of the soak case (scripts/soak: 120)")
    ap.add_argument("--sanitized", action="store_true",
                    help="rbsim is built with AddressSanitizer: its resident size says nothing about leaks")
    args = ap.parse_args()
    ensure_venv(args.venv, args.requirements)
    return run_case(args, CASES[args.case])


def run_case(args, case):
    """Runs one case (a function of a Ctx) to its verdict: prints PASSED, FAILED with every
    problem, or SKIPPED, and returns the exit status. Also the driver of startup_stops.py."""
    ctx = Ctx(args)
    # ctest's timeout and Ctrl-C: end the case through the finally block (children killed,
    # namespaces deleted).
    def on_signal(sig, _frame):
        raise Failure(f"interrupted by {signal.Signals(sig).name}")
    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    status = 1
    try:
        status = case(ctx) or 0
    except Failure as e:
        ctx.failures.append(str(e))
        ctx.log(f"FAIL: {e}")
    except Exception:
        ctx.failures.append(traceback.format_exc())
        ctx.log(f"FAIL: {traceback.format_exc()}")
    finally:
        ctx.cleanup()
    elapsed = time.monotonic() - ctx.t0
    if status == SKIP:
        print(f"e2e.{args.case}: SKIPPED ({elapsed:.1f} s)")
        return SKIP
    for n in ctx.notes:
        print(f"note: {n}")
    if ctx.failures:
        print(f"e2e.{args.case}: FAILED ({len(ctx.failures)} problems, {elapsed:.1f} s)")
        for f in ctx.failures:
            print(f"  - {f}")
        return 1
    print(f"e2e.{args.case}: PASSED ({elapsed:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
