#!/usr/bin/env python3
"""REP 2011 type hashes (RIHS01) of every shipped interface type, computed by `rosbags`.

rbsim computes its hashes in C++ (tools/msgs/src/type_hash.cpp). This script computes them with an
implementation that is not ours: rosbags (pinned in scripts/requirements.txt) parses every .msg,
.srv part and .action part of tools/msgs/definitions (`get_types_from_msg`) and hashes the result
(`Typestore.hash_rihs01`). The types rosidl derives from a service or an action, which rosbags does
not derive itself, are built here from rosidl_parser's definition.py (Service, Action).

It compares the result with the table test/msgs/data/rihs01_rosbags.txt, type by type and with
the same set of types; type_hash_test.cpp compares rbsim's hashes with the same table. Together:
rbsim == table == rosbags for every message, service and action type rbsim ships and every type
rosidl derives from them. `--write` rewrites the table (after a definition changes).

rosbags 0.11.9 hashes a .msg `char` as FIELD_TYPE_CHAR (13) where rosidl maps .msg char to IDL
uint8 first (rosidl_adapter), so rosidl hashes it as FIELD_TYPE_UINT8 (3). Every char field is
mapped to uint8 here before hashing; the script checks that this mapping is what makes rosbags
agree with rosidl's published hash of service_msgs/msg/ServiceEventInfo (char[16] client_gid).

Plain Python (no pytest). Exit status 0 when everything holds, 1 otherwise. Started with any
Python 3: it re-executes itself with the venv's interpreter (scripts/setup makes it); a missing
venv is a failure with instructions, never a skip.
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support", "python"))
from rbsim_venv import ensure_venv  # noqa: E402  (test/support/python: into the venv scripts/setup makes)

# rosidl_generator_type_description's output for service_msgs/msg/ServiceEventInfo (Jazzy), as
# published in RosLibRust/roslibrust roslibrust_codegen/assets/AddTwoInts.json ("type_hashes") and
# addinedu-ros-9th/ros-repo-4 install/robot_interfaces/share/robot_interfaces/action/NavigateToGoal.json.
PUBLISHED_SERVICE_EVENT_INFO = "RIHS01_41bcbbe07a75c9b52bc96bfd5c24d7f0fc0a08c0cb7921b3373c5732345a6f45"

# An action with rosidl's published hashes: robot_interfaces/action/NavigateToGoal, whose fields
# (below, as .action text) and hash are in the rosidl_generator_type_description output
# addinedu-ros-9th/ros-repo-4 install/robot_interfaces/share/robot_interfaces/action/NavigateToGoal.json
# (type_description_msg, type_hashes). The action's hash covers the descriptions of all twelve types
# rosidl derives from it, so it checks the derivation below.
NAVIGATE_TO_GOAL = "robot_interfaces/action/NavigateToGoal"
NAVIGATE_TO_GOAL_TEXT = ("int32 robot_id\ngeometry_msgs/PoseStamped target_pose\n---\nbool success\nstring message\n"
                         "---\ngeometry_msgs/PoseStamped current_pose\nstring current_status\n")
PUBLISHED_NAVIGATE_TO_GOAL = "RIHS01_2eb7694618e36a43a93246acd54c7ffe2139e450666d199d3d1310f4efb7fada"

# rosidl_parser/definition.py: the names rosidl gives the types of a service and an action.
SERVICE_SUFFIXES = ("_Request", "_Response", "_Event")
ACTION_SUFFIXES = ("_Goal", "_Result", "_Feedback", "_SendGoal", "_SendGoal_Request", "_SendGoal_Response",
                   "_SendGoal_Event", "_GetResult", "_GetResult_Request", "_GetResult_Response",
                   "_GetResult_Event", "_FeedbackMessage")


def read_definitions(root: str) -> dict:
    """{"pkg/msg/Name" | "pkg/srv/Name" | "pkg/action/Name": text} of every definition under root."""
    definitions = {}
    for package in sorted(os.listdir(root)):
        for kind in ("msg", "srv", "action"):
            folder = os.path.join(root, package, kind)
            if not os.path.isdir(folder):
                continue
            for file in sorted(os.listdir(folder)):
                stem, ext = os.path.splitext(file)
                if ext == "." + kind:
                    with open(os.path.join(folder, file), encoding="utf-8") as f:
                        definitions[f"{package}/{kind}/{stem}"] = f.read()
    return definitions


def split_parts(name: str, text: str, count: int) -> list:
    """The parts of a .srv (2) or .action (3) text, split at its "---" lines as rosidl_adapter does."""
    parts = [[]]
    for line in text.splitlines():
        if line.rstrip() == "---":
            parts.append([])
        else:
            parts[-1].append(line)
    if len(parts) != count:
        raise ValueError(f"{name}: {len(parts) - 1} '---' lines, want {count - 1}")
    return ["\n".join(p) + "\n" for p in parts]


def char_as_uint8(desc):
    """rosidl maps .msg char to uint8 (rosidl_adapter's MSG_TYPE_TO_IDL); rosbags 0.11.9 keeps char."""
    from rosbags.typesys.base import Nodetype

    kind, rest = desc
    if kind == Nodetype.BASE:
        return (kind, ("uint8", rest[1])) if rest[0] == "char" else desc
    if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return (kind, (char_as_uint8(rest[0]), rest[1]))
    return desc


def parse(name: str, text: str, map_char: bool) -> tuple:
    """rosbags' (constants, fields) of one .msg text named `name` (any kind)."""
    from rosbags.typesys import get_types_from_msg

    # rosbags resolves a bare nested name in the owner's folder ("pkg/srv/Result"); rosidl resolves
    # it in the package's msg folder, so the text is parsed under its pkg/msg/ name.
    package, _, short = name.split("/")
    as_msg = f"{package}/msg/{short}"
    consts, fields = get_types_from_msg(text, as_msg)[as_msg]
    if map_char:
        fields = [(n, char_as_uint8(d)) for n, d in fields]
    return (consts, fields)


def nested(type_name: str):
    from rosbags.typesys.base import Nodetype

    return (Nodetype.NAME, type_name)


def service_types(service: str, request: tuple, response: tuple) -> dict:
    """rosidl_parser's Service: request, response, the event message; the service itself as
    rosidl_generator_type_description's add_srv describes it."""
    from rosbags.typesys.base import Nodetype

    def at_most_one(type_name):
        return (Nodetype.SEQUENCE, (nested(type_name), 1))

    return {
        service: ([], [("request_message", nested(service + "_Request")),
                       ("response_message", nested(service + "_Response")),
                       ("event_message", nested(service + "_Event"))]),
        service + "_Request": request,
        service + "_Response": response,
        service + "_Event": ([], [("info", nested("service_msgs/msg/ServiceEventInfo")),
                                  ("request", at_most_one(service + "_Request")),
                                  ("response", at_most_one(service + "_Response"))]),
    }


def action_types(action: str, text: str, map_char: bool) -> dict:
    """rosidl_parser's Action (goal, result, feedback, the _SendGoal and _GetResult services, the
    feedback message) and the action as rosidl_generator_type_description's add_action describes it."""
    from rosbags.typesys.base import Nodetype

    goal, result, feedback = split_parts(action, text, 3)
    uuid = ("goal_id", nested("unique_identifier_msgs/msg/UUID"))
    types = {
        action: ([], [("goal", nested(action + "_Goal")), ("result", nested(action + "_Result")),
                      ("feedback", nested(action + "_Feedback")),
                      ("send_goal_service", nested(action + "_SendGoal")),
                      ("get_result_service", nested(action + "_GetResult")),
                      ("feedback_message", nested(action + "_FeedbackMessage"))]),
        action + "_Goal": parse(action + "_Goal", goal, map_char),
        action + "_Result": parse(action + "_Result", result, map_char),
        action + "_Feedback": parse(action + "_Feedback", feedback, map_char),
        action + "_FeedbackMessage": ([], [uuid, ("feedback", nested(action + "_Feedback"))]),
    }
    types.update(service_types(
        action + "_SendGoal", ([], [uuid, ("goal", nested(action + "_Goal"))]),
        ([], [("accepted", (Nodetype.BASE, ("bool", 0))), ("stamp", nested("builtin_interfaces/msg/Time"))])))
    types.update(service_types(
        action + "_GetResult", ([], [uuid]),
        ([], [("status", (Nodetype.BASE, ("int8", 0))), ("result", nested(action + "_Result"))])))
    return types


def rosbags_types(definitions: dict, map_char: bool = True) -> dict:
    """Every type of `definitions` and every type rosidl derives from them, in rosbags' form."""
    types = {}
    for name, text in definitions.items():
        kind = name.split("/")[1]
        if kind == "msg":
            types[name] = parse(name, text, map_char)
        elif kind == "srv":
            request, response = split_parts(name, text, 2)
            types.update(service_types(name, parse(name + "_Request", request, map_char),
                                       parse(name + "_Response", response, map_char)))
        else:
            types.update(action_types(name, text, map_char))
    return types


def hashes(types: dict, names) -> dict:
    """rosbags' RIHS01 of each of `names` over `types`."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.EMPTY)
    # hash_rihs01 reads only the store's field definitions; registering would also generate Python
    # classes, which rosbags does not make for service or action names.
    store.fielddefs.update(types)
    return {name: store.hash_rihs01(name) for name in names}


def read_table(path: str) -> dict:
    table = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                name, value = line.split()
                table[name] = value
    return table


def write_table(path: str, computed: dict) -> None:
    with open(path, "w", encoding="utf-8") as f:
        f.write("# REP 2011 hashes of every type in tools/msgs/definitions and every type rosidl derives from\n"
                "# them, computed by rosbags (char as uint8, as rosidl). Written by test/python/check_type_hashes.py\n"
                "# --write, which checks it against rosbags on every test run; type_hash_test.cpp checks rbsim's.\n")
        for name in sorted(computed):
            f.write(f"{name} {computed[name]}\n")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--venv", required=True)
    parser.add_argument("--requirements", required=True)
    parser.add_argument("--definitions", required=True, help="tools/msgs/definitions")
    parser.add_argument("--table", required=True, help="test/msgs/data/rihs01_rosbags.txt")
    parser.add_argument("--write", action="store_true", help="rewrite the table instead of checking it")
    args = parser.parse_args()
    ensure_venv(args.venv, args.requirements)

    definitions = read_definitions(args.definitions)
    types = rosbags_types(definitions)
    computed = hashes(types, types.keys())
    if args.write:
        write_table(args.table, computed)
        print(f"wrote {len(computed)} hashes to {args.table}")
        return 0

    failures = []
    # Why the mapping: without it rosbags disagrees with rosidl's published ServiceEventInfo hash.
    event_info = "service_msgs/msg/ServiceEventInfo"
    unmapped = hashes(rosbags_types({event_info: definitions[event_info]}, map_char=False), [event_info])
    if unmapped[event_info] == PUBLISHED_SERVICE_EVENT_INFO:
        failures.append(f"{event_info}: rosbags without char -> uint8 now agrees with rosidl; drop the mapping")
    if computed[event_info] != PUBLISHED_SERVICE_EVENT_INFO:
        failures.append(f"{event_info}: {computed[event_info]}, rosidl published {PUBLISHED_SERVICE_EVENT_INFO}")

    with_action = dict(definitions)
    with_action[NAVIGATE_TO_GOAL] = NAVIGATE_TO_GOAL_TEXT
    navigate = hashes(rosbags_types(with_action), [NAVIGATE_TO_GOAL])[NAVIGATE_TO_GOAL]
    if navigate != PUBLISHED_NAVIGATE_TO_GOAL:
        failures.append(f"{NAVIGATE_TO_GOAL}: {navigate}, rosidl published {PUBLISHED_NAVIGATE_TO_GOAL}")

    table = read_table(args.table)
    for name in sorted(set(computed) | set(table)):
        if name not in table:
            failures.append(f"{name}: not in {args.table} (rosbags: {computed[name]}); run with --write")
        elif name not in computed:
            failures.append(f"{name}: in {args.table} but no definition gives it")
        elif table[name] != computed[name]:
            failures.append(f"{name}: table {table[name]}, rosbags {computed[name]}")
    kinds = {k: sum(1 for n in definitions if f"/{k}/" in n) for k in ("msg", "srv", "action")}
    print(f"rosbags: {len(computed)} types ({kinds['msg']} messages, {kinds['srv']} services, "
          f"{kinds['action']} actions and the types rosidl derives from them)")
    for f in failures:
        print(f"FAIL: {f}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
