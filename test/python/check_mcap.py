#!/usr/bin/env python3
"""Cross-check of `rbsim run --record` against the official MCAP readers.

Runs the real rbsim binary on a scene with --record (MCAP), --csv, --energy-csv and --fosssim-out
in one run, then reads the recording with the official Python `mcap` reader (CRCs validated) and
`mcap-ros2-support` (CDR decoding driven by the file's own ros2msg schemas) and checks:

  * the rosbag2 layout: profile "ros2", every schema "ros2msg", every channel "cdr" with an
    "offered_qos_profiles" YAML profile (history/depth/reliability/durability/... present) and a
    "topic_type_hash" equal to an independent REP 2011 hash of tools/msgs/definitions;
  * every schema's text byte for byte against an independent implementation of rosbag2's
    LocalMessageDefinitionSource::get_full_text() over tools/msgs/definitions;
  * every message of every topic decodes, and the decoded values equal the run's own outputs:
    body states and per-body energy terms bit-exact against the CSV (shortest round-trip decimals)
    and the FOSSSim binary, totals against the energy CSV, /tf against x, y, theta, the springs
    marker against the spring states, /clock and all stamps against step * dt, the scene
    description's masses and inertias against the FOSSSim constants block, the latched markers'
    hulls (triangle areas), outlines and anchors against the scene description;
  * message counts per topic (steps + 1 per-step topics, 1 scene description and markers; fewer with
    --record-every), sequence numbers, the Statistics record, data-section and summary CRCs;
  * the indexed (seeking) reader's topic / time-range queries return exactly the right subset.

Plain Python (no pytest). Exit status 0 when everything holds, 1 otherwise (every failure listed).
Started with any Python 3: it re-executes itself with the venv's interpreter (scripts/setup makes
it); a missing venv is a failure with instructions, never a skip.
"""

import argparse
import array
import csv
import hashlib
import io
import json
import math
import os
import re
import struct
import subprocess
import sys
import warnings
import zlib

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support", "python"))
from rbsim_venv import ensure_venv  # noqa: E402  (test/support/python: into the venv scripts/setup makes)


def fail_now(message: str) -> None:
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


# ---------------------------------------------------------------------------------------------
# Failure collection: every check runs, the first few failures of each kind are shown.


class Checks:
    def __init__(self) -> None:
        self.failures = {}  # kind -> [count, [first messages]]
        self.passed = 0

    def check(self, ok: bool, kind: str, detail="") -> bool:
        if ok:
            self.passed += 1
            return True
        entry = self.failures.setdefault(kind, [0, []])
        entry[0] += 1
        if len(entry[1]) < 5:
            entry[1].append(detail() if callable(detail) else detail)
        return False

    def equal(self, actual, expected, kind: str, where="") -> bool:
        """Exact equality; floats compare bit for bit (0.0 != -0.0, NaN == NaN)."""
        return self.check(same(actual, expected), kind,
                          lambda: f"{where}: got {actual!r}, expected {expected!r}")

    def close(self, actual, expected, kind: str, where="", rel=1e-12, abs_=1e-12) -> bool:
        ok = abs(actual - expected) <= abs_ + rel * abs(expected)
        return self.check(ok, kind, lambda: f"{where}: got {actual!r}, expected {expected!r} "
                                            f"(tolerance {abs_:g} + {rel:g} relative)")

    def report(self) -> int:
        if not self.failures:
            print(f"PASS: {self.passed} checks")
            return 0
        total = sum(c for c, _ in self.failures.values())
        print(f"FAIL: {total} failed checks ({self.passed} passed)")
        for kind, (count, messages) in self.failures.items():
            print(f"  {kind}: {count} failure(s)")
            for m in messages:
                print(f"    {m}")
            if count > len(messages):
                print(f"    ... and {count - len(messages)} more")
        return 1


def same(a, b) -> bool:
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) or isinstance(b, float):
        return struct.pack("<d", float(a)) == struct.pack("<d", float(b))
    return a == b


# ---------------------------------------------------------------------------------------------
# What the recording must contain (the rosbag2 layout of rbsim's topics), written out here rather
# than taken from the C++ code under test.

TOPICS = {
    # topic: (type, transient_local, per_step)
    "/rbsim/scene": ("rbsim_msgs/msg/SceneDescription", True, False),
    "/rbsim/body_states": ("rbsim_msgs/msg/BodyStates", False, True),
    "/rbsim/spring_states": ("rbsim_msgs/msg/SpringStates", False, True),
    "/rbsim/energy": ("rbsim_msgs/msg/EnergyTerms", False, True),
    "/rbsim/markers": ("visualization_msgs/msg/MarkerArray", True, False),
    "/tf": ("tf2_msgs/msg/TFMessage", False, True),
    "/rbsim/springs": ("visualization_msgs/msg/Marker", False, True),
    "/clock": ("rosgraph_msgs/msg/Clock", False, True),
}

# ---------------------------------------------------------------------------------------------
# rosbag2's schema text (rosbag2_cpp LocalMessageDefinitionSource::get_full_text, .msg format),
# re-implemented from rosbag2's source: dependencies are the field types matched by its regex (those
# without a package get the package of the text they appear in; the primitive types are skipped),
# kept in a std::set (sorted, unique); the full text is the root's .msg file followed, depth first,
# by each dependency not seen before as "\n" + 80 '=' + "\nMSG: pkg/Type\n" + its own full text.

_MSG_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+", re.ASCII)
_PACKAGE_TYPENAME = re.compile(r"^([a-zA-Z0-9_]+)/(?:msg/)?([a-zA-Z0-9_]+)$", re.ASCII)
_PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
               "int32", "uint32", "int64", "uint64", "string"}
_MAX_RECURSION_DEPTH = 50


def rosbag2_msg_dependencies(text: str, package: str):
    deps = set()
    for m in _MSG_FIELD_TYPE.finditer(text):
        type_ = m.group(1)
        if type_ in _PRIMITIVES:
            continue
        deps.add(type_ if "/" in type_ else package + "/" + type_)
    return sorted(deps)  # std::set<std::string> order: byte-wise


def rosbag2_full_text(root_type: str, definitions_dir: str) -> bytes:
    seen = set()

    def load(type_name: str):
        m = _PACKAGE_TYPENAME.fullmatch(type_name)
        if not m:
            raise ValueError(f"invalid type name {type_name!r}")
        path = os.path.join(definitions_dir, m.group(1), "msg", m.group(2) + ".msg")
        with open(path, "rb") as f:
            text = f.read().decode()
        return text, m.group(1)

    def append_recursive(type_name: str, depth: int) -> str:
        if depth <= 0:
            raise RecursionError(f"message definitions nest deeper than 50 at {type_name}")
        text, package = load(type_name)
        result = text
        for dep in rosbag2_msg_dependencies(text, package):
            if dep in seen:
                continue
            seen.add(dep)
            result += "\n" + "=" * 80 + "\n" + "MSG: " + dep + "\n"
            result += append_recursive(dep, depth - 1)
        return result

    return append_recursive(root_type, _MAX_RECURSION_DEPTH).encode()


# ---------------------------------------------------------------------------------------------
# topic_type_hash: the REP 2011 hash rosbag2 (Jazzy) writes per channel, written here from REP 2011
# and rosidl_generator_type_description's description (not from rbsim's code): field type ids of
# type_description_interfaces/msg/FieldType (.msg char is IDL uint8), +48 fixed array, +96
# bounded, +144 unbounded sequence; referenced types sorted; json.dumps(", ", ": "); SHA-256.

_FIELD_TYPE_IDS = {"int8": 2, "uint8": 3, "char": 3, "int16": 4, "uint16": 5, "int32": 6, "uint32": 7,
                   "int64": 8, "uint64": 9, "float32": 10, "float64": 11, "bool": 15, "byte": 16,
                   "string": 17}


def _hash_fields(type_name: str, definitions_dir: str) -> list:
    pkg, _, name = type_name.split("/")
    with open(os.path.join(definitions_dir, pkg, "msg", name + ".msg"), encoding="utf-8") as f:
        text = f.read()
    fields = []
    for raw in text.splitlines():
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        ftype, fname = words[0], words[1]
        if "=" in fname or (len(words) > 2 and words[2].startswith("=")):
            continue  # a constant
        base, capacity, offset = ftype, 0, 0
        array_m = re.fullmatch(r"(.+)\[(<=)?(\d*)\]", ftype)
        if array_m:
            base = array_m.group(1)
            if array_m.group(3) and not array_m.group(2):
                capacity, offset = int(array_m.group(3)), 48
            elif array_m.group(3):
                capacity, offset = int(array_m.group(3)), 96
            else:
                offset = 144
        string_capacity, nested = 0, ""
        bounded_m = re.fullmatch(r"string<=(\d+)", base)
        if bounded_m:
            type_id, string_capacity = 21, int(bounded_m.group(1))
        elif base in _FIELD_TYPE_IDS:
            type_id = _FIELD_TYPE_IDS[base]
        else:
            type_id = 1
            parts = base.split("/")
            nested = "std_msgs/msg/Header" if base == "Header" else (
                f"{pkg}/msg/{parts[0]}" if len(parts) == 1 else f"{parts[0]}/msg/{parts[-1]}")
        fields.append({"name": fname, "type": {"type_id": type_id + offset, "capacity": capacity,
                                               "string_capacity": string_capacity,
                                               "nested_type_name": nested}})
    if not fields:
        fields.append({"name": "structure_needs_at_least_one_member",
                       "type": {"type_id": 3, "capacity": 0, "string_capacity": 0, "nested_type_name": ""}})
    return fields


def rep2011_type_hash(root_type: str, definitions_dir: str) -> str:
    described = {root_type: _hash_fields(root_type, definitions_dir)}
    pending = [f["type"]["nested_type_name"] for f in described[root_type] if f["type"]["nested_type_name"]]
    referenced = set()
    while pending:
        t = pending.pop()
        if t in referenced:
            continue
        referenced.add(t)
        described[t] = _hash_fields(t, definitions_dir)
        pending += [f["type"]["nested_type_name"] for f in described[t] if f["type"]["nested_type_name"]]
    description = {
        "type_description": {"type_name": root_type, "fields": described[root_type]},
        "referenced_type_descriptions": [{"type_name": t, "fields": described[t]} for t in sorted(referenced)],
    }
    text = json.dumps(description, ensure_ascii=True, separators=(", ", ": "))
    return "RIHS01_" + hashlib.sha256(text.encode("utf-8")).hexdigest()


# ---------------------------------------------------------------------------------------------
# offered_qos_profiles: the YAML rosbag2 writes (a sequence of maps, durations as sec/nsec maps).
# A small parser for that subset; anything else is reported as unparseable.


def parse_qos_yaml(text: str):
    profiles, current, nested = [], None, None
    for number, raw in enumerate(text.split("\n"), 1):
        if not raw.strip():
            continue
        line = raw
        if line.startswith("- "):
            current, nested = {}, None
            profiles.append(current)
            line = "  " + line[2:]
        if current is None or ":" not in line:
            raise ValueError(f"line {number}: {raw!r}")
        indent = len(line) - len(line.lstrip(" "))
        key, value = (s.strip() for s in line.strip().split(":", 1))
        if indent == 2:
            if value == "":
                nested = {}
                current[key] = nested
            else:
                current[key], nested = value, None
        elif indent == 4 and nested is not None:
            nested[key] = value
        else:
            raise ValueError(f"line {number}: unexpected indentation: {raw!r}")
    return profiles


def check_qos(c: Checks, topic: str, text: str, transient_local: bool) -> None:
    kind = "offered_qos_profiles"
    try:
        profiles = parse_qos_yaml(text)
    except ValueError as e:
        c.check(False, kind, f"{topic}: not parseable: {e}\n{text}")
        return
    if not c.check(len(profiles) == 1, kind, f"{topic}: {len(profiles)} profiles, expected 1"):
        return
    p = profiles[0]
    for key in ("history", "depth", "reliability", "durability", "deadline", "lifespan", "liveliness",
                "liveliness_lease_duration", "avoid_ros_namespace_conventions"):
        c.check(key in p, kind, f"{topic}: no {key!r} in {p}")
    # What rbsim's node offers: the scene keep last 1, per-step topics keep all (no depth).
    c.equal(p.get("history"), "keep_last" if transient_local else "keep_all", kind, f"{topic} history")
    c.equal(p.get("depth"), "1" if transient_local else "0", kind, f"{topic} depth")
    c.equal(p.get("reliability"), "reliable", kind, f"{topic} reliability")
    c.equal(p.get("durability"), "transient_local" if transient_local else "volatile", kind, f"{topic} durability")
    c.equal(p.get("liveliness"), "automatic", kind, f"{topic} liveliness")
    c.equal(p.get("avoid_ros_namespace_conventions"), "false", kind, f"{topic} avoid_ros_namespace_conventions")
    for key in ("deadline", "lifespan", "liveliness_lease_duration"):
        d = p.get(key)
        c.check(isinstance(d, dict) and set(d) == {"sec", "nsec"} and all(v.isdigit() for v in d.values()),
                kind, f"{topic}: {key} is {d!r}, expected a sec/nsec map")


# ---------------------------------------------------------------------------------------------
# The run's own outputs


def read_csv(path: str):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def read_fosssim(path: str, bodies: int):
    values = array.array("d")
    with open(path, "rb") as f:
        values.frombytes(f.read())
    if sys.byteorder != "little":
        values.byteswap()
    head, per_step = 16 * bodies + 1, 12 * bodies + 1
    if len(values) < head or (len(values) - head) % per_step:
        raise ValueError(f"{path}: {len(values)} doubles do not fit {bodies} bodies")
    at = 0
    frames = []
    constants = {}

    def frame(with_constants):
        nonlocal at
        f = {"state": [values[at + 6 * b: at + 6 * b + 6] for b in range(bodies)]}
        at += 6 * bodies
        if with_constants:
            constants["M"] = list(values[at: at + bodies])
            at += bodies
            constants["X"] = [(values[at + 2 * b], values[at + 2 * b + 1]) for b in range(bodies)]
            at += 2 * bodies
            constants["I"] = list(values[at: at + bodies])
            at += bodies
        f["P"] = [(values[at + 2 * b], values[at + 2 * b + 1]) for b in range(bodies)]
        at += 2 * bodies
        for name in ("L_point", "L_spin", "T_point", "T_spin"):
            f[name] = list(values[at: at + bodies])
            at += bodies
        f["U"] = values[at]
        at += 1
        frames.append(f)

    frame(True)
    while at < len(values):
        frame(False)
    return constants, frames


def sim_time_ns(t: float) -> int:
    """std::round(t * 1e9) (half away from zero), clamped at 0, exactly as rbsim stamps messages."""
    x = t * 1e9
    if x <= 0.0:
        return 0
    whole = math.floor(x)
    return int(whole) + (1 if x - whole >= 0.5 else 0)


def split_ns(ns: int):
    return ns // 1_000_000_000, ns % 1_000_000_000


# ---------------------------------------------------------------------------------------------
# The checks


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--venv", required=True, help="venv made by scripts/setup (<build>/venv)")
    ap.add_argument("--requirements", required=True, help="scripts/requirements.txt")
    ap.add_argument("--rbsim", required=True, help="the rbsim binary")
    ap.add_argument("--scene", required=True)
    ap.add_argument("--steps", type=int, required=True)
    ap.add_argument("--compression", choices=["zstd", "lz4", "none"], required=True)
    ap.add_argument("--record-every", type=int, default=1)
    ap.add_argument("--definitions", required=True, help="tools/msgs/definitions")
    ap.add_argument("--workdir", required=True)
    ap.add_argument("--min-chunks", type=int, default=1, help="fail when the file has fewer chunks")
    args = ap.parse_args()

    ensure_venv(args.venv, args.requirements)

    from mcap.reader import make_reader, NonSeekingReader
    from mcap_ros2.decoder import DecoderFactory

    os.makedirs(args.workdir, exist_ok=True)
    out = lambda name: os.path.join(args.workdir, name)  # noqa: E731
    mcap_path, csv_path, energy_path, fosssim_path = out("run.mcap"), out("run.csv"), out("energy.csv"), out("run.bin")
    for p in (mcap_path, csv_path, energy_path, fosssim_path):
        if os.path.exists(p):
            os.remove(p)
    cmd = [args.rbsim, "run", args.scene, "--steps", str(args.steps), "--record", mcap_path,
           "--compression", args.compression, "--record-every", str(args.record_every), "--csv", csv_path,
           "--energy-csv", energy_path, "--fosssim-out", fosssim_path, "--progress", "never"]
    print("$ " + " ".join(cmd), flush=True)
    run = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    sys.stderr.write(run.stderr)
    if run.returncode != 0:
        fail_now(f"rbsim run exited with status {run.returncode}")

    c = Checks()
    steps, every = args.steps, args.record_every
    recorded = list(range(0, steps + 1, every))  # step 0 always, then every k-th step

    # The run's own outputs. CSV numbers are shortest round-trip decimals: float() reads them back
    # bit-exact, so every comparison below is exact.
    header, rows = read_csv(csv_path)
    c.equal(header, "step,t,body,x,y,theta,vx,vy,omega,px,py,L_point,L_spin,T_point,T_spin".split(","),
            "csv header")
    csv_by_step = {}
    for r in rows:
        csv_by_step.setdefault(int(r[0]), []).append([float(v) for v in r[1:]])
    bodies = len(csv_by_step.get(0, []))
    c.equal(sorted(csv_by_step), list(range(steps + 1)), "csv steps")
    eheader, erows = read_csv(energy_path)
    c.equal(eheader, "step,t,U,T_point,T_spin,T,E,U_gravity,U_spring,px,py,L".split(","), "energy csv header")
    energy_by_step = {int(r[0]): dict(zip(eheader[1:], (float(v) for v in r[1:]))) for r in erows}
    constants, frames = read_fosssim(fosssim_path, bodies)
    c.equal(len(frames), steps + 1, "fosssim frames")

    with open(mcap_path, "rb") as f:
        data = f.read()
    print(f"{mcap_path}: {len(data)} bytes, {bodies} bodies, {steps} steps, record every {every}, "
          f"compression {args.compression}")

    # --- Whole-file pass with the streaming reader: chunk CRCs and the data-section CRC.
    try:
        stream_count = sum(1 for _ in NonSeekingReader(io.BytesIO(data), validate_crcs=True).iter_messages(
            log_time_order=False))
    except Exception as e:  # noqa: BLE001: any reader error is the finding
        c.check(False, "streaming read (validate_crcs=True)", f"{type(e).__name__}: {e}")
        stream_count = None

    # Summary CRC (the reader does not check it): CRC-32 of the summary section through the Footer's
    # summary_offset_start field.
    magic = b"\x89MCAP0\r\n"
    c.check(data[:8] == magic and data[-8:] == magic, "magic", "leading/trailing magic bytes")
    fo = len(data) - 8 - (1 + 8 + 20)
    opcode, length = struct.unpack_from("<BQ", data, fo)
    summary_start, summary_offset_start, summary_crc = struct.unpack_from("<QQI", data, fo + 9)
    c.check(opcode == 0x02 and length == 20, "footer", f"footer opcode {opcode:#x} length {length}")
    c.check(summary_start != 0 and summary_crc != 0, "summary crc", "no summary or no summary CRC")
    if summary_start:
        crc = zlib.crc32(data[summary_start: fo + 9 + 16])
        c.check(crc == summary_crc, "summary crc", f"computed {crc:#010x}, footer says {summary_crc:#010x}")

    # --- Seeking (indexed) reader with CRC validation and the ROS 2 decoder.
    reader = make_reader(io.BytesIO(data), validate_crcs=True, decoder_factories=[DecoderFactory()])
    hdr = reader.get_header()
    c.equal(hdr.profile, "ros2", "header profile")
    c.check(hdr.library.startswith("rbsim"), "header library", f"library {hdr.library!r}")
    summary = reader.get_summary()
    if summary is None:
        c.check(False, "summary", "file has no summary section")
        return c.report()
    c.check(len(summary.chunk_indexes) >= args.min_chunks, "chunk count",
            f"{len(summary.chunk_indexes)} chunks, expected at least {args.min_chunks}")
    for ci in summary.chunk_indexes:
        c.equal(ci.compression, "" if args.compression == "none" else args.compression, "chunk compression")

    channels_by_topic = {ch.topic: ch for ch in summary.channels.values()}
    c.equal(sorted(channels_by_topic), sorted(TOPICS), "topics")
    for schema in summary.schemas.values():
        c.equal(schema.encoding, "ros2msg", "schema encoding", schema.name)
    for topic, ch in channels_by_topic.items():
        c.equal(ch.message_encoding, "cdr", "message encoding", topic)
        if topic not in TOPICS:
            continue
        type_name, transient_local, _ = TOPICS[topic]
        schema = summary.schemas.get(ch.schema_id)
        if not c.check(schema is not None, "channel schema", f"{topic}: schema id {ch.schema_id} not in summary"):
            continue
        c.equal(schema.name, type_name, "schema name", topic)
        c.check("offered_qos_profiles" in ch.metadata, "offered_qos_profiles", f"{topic}: metadata {ch.metadata}")
        check_qos(c, topic, ch.metadata.get("offered_qos_profiles", ""), transient_local)
        c.equal(ch.metadata.get("topic_type_hash"), rep2011_type_hash(type_name, args.definitions),
                "topic_type_hash (REP 2011)", topic)
        expected_text = rosbag2_full_text(type_name, args.definitions)
        c.check(schema.data == expected_text, "schema text (rosbag2 algorithm)",
                lambda: f"{topic} ({type_name}): file schema differs from rosbag2's at byte "
                        f"{next((i for i, (a, b) in enumerate(zip(schema.data, expected_text)) if a != b), min(len(schema.data), len(expected_text)))}"
                        f" (lengths {len(schema.data)} vs {len(expected_text)})")

    # --- Decode every message of every topic.
    decoded = {topic: [] for topic in TOPICS}
    everything = []
    try:
        for schema, channel, message, msg in reader.iter_decoded_messages():
            decoded.setdefault(channel.topic, []).append((message, msg))
            everything.append((channel.topic, message))
    except Exception as e:  # noqa: BLE001
        c.check(False, "decode", f"iter_decoded_messages failed: {type(e).__name__}: {e}")
        return c.report()
    if stream_count is not None:
        c.equal(stream_count, len(everything), "message count (streaming vs indexed)")
    times = [m.log_time for _, m in everything]
    c.check(times == sorted(times), "log-time order", "indexed reader output not in log-time order")

    # Counts per topic, sequences, Statistics, CDR encapsulation.
    stats = summary.statistics
    for topic, (_, _, per_step) in TOPICS.items():
        expected = len(recorded) if per_step else 1
        msgs = decoded.get(topic, [])
        c.equal(len(msgs), expected, "message count", topic)
        ch = channels_by_topic.get(topic)
        if stats is not None and ch is not None:
            c.equal(stats.channel_message_counts.get(ch.id), expected, "statistics channel_message_counts", topic)
        c.equal([m.sequence for m, _ in msgs], list(range(len(msgs))), "sequence numbers", topic)
        for m, _ in msgs:
            c.check(m.log_time == m.publish_time, "publish_time", f"{topic}: {m.log_time} vs {m.publish_time}")
            c.check(m.data[:3] == b"\x00\x01\x00", "CDR encapsulation",
                    f"{topic}: header {m.data[:4].hex()} (expected 00 01 00 xx: CDR little endian)")
    if stats is not None:
        c.equal(stats.message_count, len(everything), "statistics message_count")
        c.equal(stats.message_start_time, 0, "statistics message_start_time")
        c.equal(stats.message_end_time, max(times) if times else 0, "statistics message_end_time")

    # --- Scene description vs the FOSSSim constants block and the scene's forces.
    scene_msgs = decoded.get("/rbsim/scene", [])
    if not scene_msgs:
        return c.report()
    scene_message, scene = scene_msgs[0]
    c.equal(scene_message.log_time, 0, "scene log_time")
    c.equal((scene.header.stamp.sec, scene.header.stamp.nanosec, scene.header.frame_id), (0, 0, "world"),
            "scene header")
    dt = scene.dt
    c.equal(scene.step_count, math.ceil(scene.duration / dt), "scene step_count", "ceil(duration / dt)")
    c.check(scene.integrator in ("explicit-euler", "symplectic-euler"), "scene integrator", scene.integrator)
    c.equal(len(scene.bodies), bodies, "scene body count")
    for b, body in enumerate(scene.bodies):
        c.equal(body.mass, constants["M"][b], "scene mass vs FOSSSim M", f"body {b}")
        c.equal(body.inertia, constants["I"][b], "scene inertia vs FOSSSim I", f"body {b}")
        c.check(len(body.hull) >= 1, "scene hull", f"body {b}: empty hull")
        c.check(body.radius > 0, "scene radius", f"body {b}: radius {body.radius}")
        c.equal(body.color.a, 1.0, "scene body colour alpha", f"body {b}")
    n_gravity, n_springs, n_winds = len(scene.gravity), len(scene.springs), len(scene.winds)
    print(f"scene {scene.name!r}: {bodies} bodies, {n_gravity} gravity, {n_springs} springs, {n_winds} winds, "
          f"{scene.integrator}, dt {dt}; {len(summary.chunk_indexes)} chunks, {len(everything)} messages")
    for k, sp in enumerate(scene.springs):
        for end in (sp.body_i, sp.body_j):
            c.check(end == -1 or 0 <= end < bodies, "scene spring ends", f"spring {k}: body {end}")

    # --- Per-step topics against the CSV, energy CSV and FOSSSim output.
    # Messages by the step their log time stands for (a message at any other time is an error).
    step_of_time = {sim_time_ns(k * dt): k for k in recorded}
    by_step = {}
    for topic in TOPICS:
        if TOPICS[topic][2]:
            for m, msg in decoded.get(topic, []):
                k = step_of_time.get(m.log_time)
                if c.check(k is not None, "message at an unexpected time", f"{topic} log_time {m.log_time}"):
                    c.check(k not in by_step.setdefault(topic, {}), "two messages at one step", f"{topic} step {k}")
                    by_step[topic][k] = (m, msg)

    def stamp_ok(topic, step, message, stamp):
        t = csv_by_step[step][0][0]
        c.equal(t, step * dt, "csv t == step * dt", f"step {step}")
        ns = sim_time_ns(step * dt)
        c.equal(message.log_time, ns, "log_time == step * dt", f"{topic} step {step}")
        if stamp is not None:
            c.equal((stamp.sec, stamp.nanosec), split_ns(ns), "header.stamp == step * dt", f"{topic} step {step}")

    for step in recorded:
        rows_k = csv_by_step.get(step)
        if rows_k is None or len(rows_k) != bodies:
            c.check(False, "csv rows", f"step {step}: {0 if rows_k is None else len(rows_k)} rows")
            continue
        frame = frames[step] if step < len(frames) else None

        m, msg = by_step.get("/rbsim/body_states", {}).get(step, (None, None))
        if c.check(msg is not None, "missing message", f"/rbsim/body_states step {step}"):
            stamp_ok("/rbsim/body_states", step, m, msg.header.stamp)
            c.equal(msg.header.frame_id, "world", "frame_id", "/rbsim/body_states")
            c.equal(msg.step, step, "body_states step")
            c.equal(len(msg.bodies), bodies, "body_states body count", f"step {step}")
            for b, s in enumerate(msg.bodies[:bodies]):
                row = rows_k[b]  # t, body, x, y, theta, vx, vy, omega, px, py, L_point, L_spin, T_point, T_spin
                c.equal(s.id, b, "body_states id")
                got = (s.x, s.y, s.theta, s.vx, s.vy, s.omega)
                for name, g, e in zip(("x", "y", "theta", "vx", "vy", "omega"), got, row[2:8]):
                    c.equal(g, e, "body state == CSV", f"step {step} body {b} {name}")
                if frame is not None:
                    c.equal(list(got), list(frame["state"][b]), "body state == FOSSSim state", f"step {step} body {b}")
                if step == 0:
                    c.equal((s.x, s.y), constants["X"][b], "step-0 position == FOSSSim X", f"body {b}")

        m, msg = by_step.get("/rbsim/energy", {}).get(step, (None, None))
        if c.check(msg is not None, "missing message", f"/rbsim/energy step {step}"):
            stamp_ok("/rbsim/energy", step, m, msg.header.stamp)
            c.equal(msg.step, step, "energy step")
            c.equal(len(msg.bodies), bodies, "energy body count", f"step {step}")
            for b, e in enumerate(msg.bodies[:bodies]):
                row = rows_k[b]
                c.equal(e.id, b, "energy id")
                got = (e.momentum.x, e.momentum.y, e.l_point, e.l_spin, e.t_point, e.t_spin)
                for name, g, x in zip(("px", "py", "L_point", "L_spin", "T_point", "T_spin"), got, row[8:14]):
                    c.equal(g, x, "energy terms == CSV", f"step {step} body {b} {name}")
                if frame is not None:
                    ref = (*frame["P"][b], frame["L_point"][b], frame["L_spin"][b], frame["T_point"][b],
                           frame["T_spin"][b])
                    c.equal(got, ref, "energy terms == FOSSSim quantities", f"step {step} body {b}")
            tot = energy_by_step.get(step)
            if c.check(tot is not None, "energy csv rows", f"step {step} missing"):
                c.equal((msg.momentum.x, msg.momentum.y), (tot["px"], tot["py"]), "energy momentum == energy CSV",
                        f"step {step}")
                c.equal(msg.angular_momentum, tot["L"], "energy angular_momentum == energy CSV L", f"step {step}")
                c.equal(msg.kinetic_point, tot["T_point"], "energy kinetic_point == energy CSV", f"step {step}")
                c.equal(msg.kinetic_spin, tot["T_spin"], "energy kinetic_spin == energy CSV", f"step {step}")
                # Per-kind potentials: the forces summed in file order, as the energy CSV sums them.
                grav, spr = 0.0, 0.0
                for f in msg.forces:
                    if f.kind == 0:
                        grav += f.potential
                    elif f.kind == 1:
                        spr += f.potential
                c.equal(grav, tot["U_gravity"], "gravity potentials == energy CSV U_gravity", f"step {step}")
                c.equal(spr, tot["U_spring"], "spring potentials == energy CSV U_spring", f"step {step}")
                c.equal(msg.potential_gravity, tot["U_gravity"], "energy potential_gravity == energy CSV U_gravity",
                        f"step {step}")
                c.equal(msg.potential_spring, tot["U_spring"], "energy potential_spring == energy CSV U_spring",
                        f"step {step}")
                # U and E add the same terms in another order: equal up to rounding.
                scale = 1e-13 * (abs(grav) + abs(spr) + abs(msg.kinetic_point) + abs(msg.kinetic_spin) + 1.0)
                c.close(msg.potential, tot["U"], "energy potential == energy CSV U", f"step {step}", rel=0, abs_=scale)
                c.close(msg.total, tot["E"], "energy total == energy CSV E", f"step {step}", rel=0, abs_=scale)
                if frame is not None:
                    c.close(msg.potential, frame["U"], "energy potential == FOSSSim U", f"step {step}", rel=0,
                            abs_=scale)
            c.equal([(f.kind, f.index) for f in msg.forces],
                    [(0, g) for g in range(n_gravity)] + [(1, k) for k in range(n_springs)], "energy forces",
                    f"step {step}")

        m, msg = by_step.get("/tf", {}).get(step, (None, None))
        if c.check(msg is not None, "missing message", f"/tf step {step}"):
            c.equal(len(msg.transforms), bodies, "tf count", f"step {step}")
            for b, t in enumerate(msg.transforms[:bodies]):
                stamp_ok("/tf", step, m, t.header.stamp)
                c.equal((t.header.frame_id, t.child_frame_id), ("world", f"rbsim/body_{b}"), "tf frames",
                        f"step {step} body {b}")
                x, y, theta = rows_k[b][2:5]
                tr, q = t.transform.translation, t.transform.rotation
                c.equal((tr.x, tr.y, tr.z), (x, y, 0.0), "tf translation == CSV x, y", f"step {step} body {b}")
                # Rotation theta about +z: (0, 0, sin(theta/2), cos(theta/2)), same libm as rbsim.
                c.equal((q.x, q.y, q.z, q.w), (0.0, 0.0, math.sin(0.5 * theta), math.cos(0.5 * theta)),
                        "tf rotation == theta", f"step {step} body {b} theta {theta!r}")

        m, msg = by_step.get("/clock", {}).get(step, (None, None))
        if c.check(msg is not None, "missing message", f"/clock step {step}"):
            stamp_ok("/clock", step, m, None)
            c.equal((msg.clock.sec, msg.clock.nanosec), split_ns(sim_time_ns(step * dt)), "/clock == step * dt",
                    f"step {step}")

        m, springs_msg = by_step.get("/rbsim/spring_states", {}).get(step, (None, None))
        if c.check(springs_msg is not None, "missing message", f"/rbsim/spring_states step {step}"):
            stamp_ok("/rbsim/spring_states", step, m, springs_msg.header.stamp)
            c.equal(springs_msg.step, step, "spring_states step")
            c.equal(len(springs_msg.springs), n_springs, "spring count", f"step {step}")
            energy_msg = by_step.get("/rbsim/energy", {}).get(step, (None, None))[1]
            for k, (st, sp) in enumerate(zip(springs_msg.springs, scene.springs)):
                c.equal(st.id, k, "spring id")
                c.equal(st.rest_length, sp.rest_length, "spring rest_length == scene", f"spring {k}")
                ends = []
                for body, anchor in ((sp.body_i, sp.anchor_i), (sp.body_j, sp.anchor_j)):
                    if body < 0:
                        ends.append((anchor.x, anchor.y))
                    else:
                        bx, by_, th = rows_k[body][2:5]
                        cs, sn = math.cos(th), math.sin(th)
                        ends.append((bx + cs * anchor.x - sn * anchor.y, by_ + sn * anchor.x + cs * anchor.y))
                for (gx, gy), (ex, ey), name in zip(((st.end_i.x, st.end_i.y), (st.end_j.x, st.end_j.y)), ends,
                                                    ("end_i", "end_j")):
                    c.close(gx, ex, "spring end == X + R(theta) anchor", f"step {step} spring {k} {name}.x", abs_=1e-9)
                    c.close(gy, ey, "spring end == X + R(theta) anchor", f"step {step} spring {k} {name}.y", abs_=1e-9)
                length = math.hypot(st.end_j.x - st.end_i.x, st.end_j.y - st.end_i.y)
                c.close(st.length, length, "spring length", f"step {step} spring {k}", rel=1e-12, abs_=1e-12)
                c.close(st.potential, 0.5 * sp.stiffness * (st.length - sp.rest_length) ** 2, "spring potential",
                        f"step {step} spring {k}", rel=1e-9, abs_=1e-12)
                if energy_msg is not None and n_gravity + k < len(energy_msg.forces):
                    c.equal(energy_msg.forces[n_gravity + k].potential, st.potential,
                            "energy spring potential == spring_states", f"step {step} spring {k}")

        m, mk = by_step.get("/rbsim/springs", {}).get(step, (None, None))
        if c.check(mk is not None, "missing message", f"/rbsim/springs step {step}") and springs_msg is not None:
            stamp_ok("/rbsim/springs", step, m, mk.header.stamp)
            c.equal((mk.ns, mk.id, mk.type, mk.action, mk.header.frame_id), ("springs", 0, 5, 0, "world"),
                    "spring marker", f"step {step}")
            want = []
            for st in springs_msg.springs:
                want += [(st.end_i.x, st.end_i.y, 0.0), (st.end_j.x, st.end_j.y, 0.0)]
            c.equal([(pt.x, pt.y, pt.z) for pt in mk.points], want, "spring marker points == spring_states ends",
                    f"step {step}")
            colours = []
            for sp in scene.springs:
                colours += [(sp.color.r, sp.color.g, sp.color.b, sp.color.a)] * 2
            # Springs that share one colour: it is the marker's color, and colors is empty (a
            # viewer then draws every vertex in color); otherwise one colour per vertex.
            got = [(cl.r, cl.g, cl.b, cl.a) for cl in mk.colors]
            if not got and len(set(colours)) == 1:
                got = [(mk.color.r, mk.color.g, mk.color.b, mk.color.a)] * len(mk.points)
            c.equal(got, colours, "spring marker colours", f"step {step}")

    # --- The latched markers, once at step 0: per body its hull filled (TRIANGLE_LIST, triangle areas
    # summing to the hull's) and outlined (closed LINE_STRIP of width 2 r) in its frame; fixed anchors.
    markers = decoded.get("/rbsim/markers", [])
    if markers:
        m, msg = markers[0]
        c.equal(m.log_time, 0, "markers log_time")
        anchors = []
        for sp in scene.springs:
            for body, a in ((sp.body_i, sp.anchor_i), (sp.body_j, sp.anchor_j)):
                if body < 0:
                    anchors.append((a.x, a.y, 0.0))
        c.equal(len(msg.markers), 2 * bodies + (1 if anchors else 0), "marker count")
        for b, body in enumerate(scene.bodies[: len(msg.markers) // 2]):
            fill, line = msg.markers[2 * b], msg.markers[2 * b + 1]
            for mk in (fill, line):
                c.equal((mk.header.frame_id, mk.frame_locked, mk.lifetime.sec, mk.lifetime.nanosec),
                        (f"rbsim/body_{b}", True, 0, 0), "body marker frame", f"body {b}")
                c.equal((mk.color.r, mk.color.g, mk.color.b, mk.color.a),
                        (body.color.r, body.color.g, body.color.b, body.color.a), "body marker colour", f"body {b}")
            hull = [(v.x, v.y) for v in body.hull]
            area = abs(sum(hull[i][0] * hull[(i + 1) % len(hull)][1] - hull[(i + 1) % len(hull)][0] * hull[i][1]
                           for i in range(len(hull)))) / 2
            pts = [(p.x, p.y) for p in fill.points]
            tiles = sum(((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0])) / 2
                        for p0, p1, p2 in zip(pts[0::3], pts[1::3], pts[2::3]))
            c.equal(fill.type, 11, "hull marker type", f"body {b}")
            c.close(tiles, area, "hull triangles' area == hull area", f"body {b}", rel=1e-9, abs_=1e-15)
            c.equal(line.type, 4, "outline marker type", f"body {b}")
            c.equal(line.scale.x, 2.0 * body.radius, "outline width == 2 r", f"body {b}")
            c.equal([(p.x, p.y, p.z) for p in line.points], [(x, y, 0.0) for x, y in hull + hull[:1]],
                    "outline == hull", f"body {b}")
        if anchors and len(msg.markers) == 2 * bodies + 1:
            mk = msg.markers[-1]
            c.equal((mk.type, mk.header.frame_id), (7, "world"), "anchor marker")
            c.equal([(p.x, p.y, p.z) for p in mk.points], anchors, "anchor marker points == fixed spring ends")

    # --- Indexed reader queries: topic and time-range views against the full decode.
    def view(topics=None, **bounds):
        r = make_reader(io.BytesIO(data), validate_crcs=True)
        return [(ch.topic, m.log_time, m.sequence, m.data) for _, ch, m in r.iter_messages(topics=topics, **bounds)]

    full = [(t, m.log_time, m.sequence, m.data) for t, m in everything]
    c.equal(view(), full, "indexed view: all messages")
    ts = [sim_time_ns(k * dt) for k in recorded]
    lo, hi = ts[len(ts) // 3], ts[(2 * len(ts)) // 3]
    pair = ["/rbsim/body_states", "/clock"]
    want = [x for x in full if x[0] in pair and lo <= x[1] < hi]
    got = view(pair, starting_at=lo, ending_before=hi)
    c.check(got == want, "indexed view: topics + [start, end)",
            lambda: f"{len(got)} messages, expected {len(want)} ({pair}, [{lo}, {hi}))")
    in_range = sum(1 for t in ts if lo <= t < hi)
    c.equal(len(got), 2 * in_range, "indexed view: topics + [start, end) count", f"[{lo}, {hi})")
    with warnings.catch_warnings():  # start_time / end_time: deprecated aliases of the two above
        warnings.simplefilter("ignore", DeprecationWarning)
        c.check(view(pair, start_time=lo, end_time=hi) == want, "indexed view: start_time/end_time",
                "differs from starting_at/ending_before")
    want_incl = [x for x in full if x[0] in pair and lo <= x[1] <= hi]
    c.check(view(pair, starting_at=lo, ending_at=hi) == want_incl, "indexed view: ending_at (inclusive)",
            f"expected {len(want_incl)} messages")
    one = "/rbsim/energy"
    c.check(view(one, starting_after=lo) == [x for x in full if x[0] == one and x[1] > lo],
            "indexed view: single topic, starting_after", one)
    c.check(view(["/rbsim/scene"]) == [x for x in full if x[0] == "/rbsim/scene"], "indexed view: scene only", "")
    c.equal(view(None, starting_at=lo, ending_before=lo), [], "indexed view: empty range")
    c.equal(view(["/rbsim/springs"], starting_at=ts[-1] + 1), [], "indexed view: after the end")
    # Every message at the first recorded time after step 0 (all per-step topics, no scene).
    if len(ts) > 1:
        got = view(None, starting_at=ts[1], ending_at=ts[1])
        c.equal(sorted(x[0] for x in got), sorted(t for t in TOPICS if TOPICS[t][2]), "indexed view: one instant")
    rev = view(pair, reverse=True)
    c.check([x[1] for x in rev] == sorted((x[1] for x in rev), reverse=True) and sorted(rev) == sorted(
        x for x in full if x[0] in pair), "indexed view: reverse", "")

    return c.report()


if __name__ == "__main__":
    sys.exit(main())
