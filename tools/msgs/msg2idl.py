#!/usr/bin/env python3
"""Generates OMG IDL from the .msg definitions, for Cyclone DDS's idlc.

The types land where ROS 2's rmw_cyclonedds_cpp puts them, so DDS type names follow the ROS 2
convention: pkg/msg/Name becomes struct pkg::msg::dds_::Name_. The .msg files stay the one
source of truth; this runs at build time.

usage: msg2idl.py DEFINITIONS_DIR OUT_DIR   (writes OUT_DIR/<pkg>/msg/<Name>.idl)
"""
import pathlib
import re
import sys

PRIMITIVES = {
    "bool": "boolean", "byte": "octet", "char": "uint8", "int8": "int8", "uint8": "uint8",
    "int16": "short", "uint16": "unsigned short", "int32": "long", "uint32": "unsigned long",
    "int64": "long long", "uint64": "unsigned long long", "float32": "float", "float64": "double",
    "string": "string",
}


def idl_type(msg_type, package):
    if msg_type in PRIMITIVES:
        return PRIMITIVES[msg_type], None
    bounded = re.fullmatch(r"string<=(\d+)", msg_type)
    if bounded:  # string<=N: a bounded IDL string (same CDR as a string)
        return f"string<{bounded.group(1)}>", None
    parts = msg_type.split("/")
    pkg, name = (package, parts[0]) if len(parts) == 1 else (parts[0], parts[-1])
    return f"{pkg}::msg::dds_::{name}_", f"{pkg}/msg/{name}"


def convert(package, name, text):
    fields, consts, includes = [], [], []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        m = re.match(r"^([\w/]+(?:<=\d+)?)(\[(<=)?(\d*)\])?\s+(\w+)\s*(=\s*(.+))?(\s+.*)?$", line)
        if not m:
            sys.exit(f"msg2idl: {package}/{name}: cannot parse '{raw}'")
        base, array, bounded, size, field, _, const_value, _ = m.groups()
        t, dep = idl_type(base, package)
        if dep and dep not in includes:
            includes.append(dep)
        if const_value is not None:
            consts.append(f"      const {t} {field} = {const_value.strip()};")
        elif array and (not size or bounded):
            fields.append(f"      sequence<{t}> {field};")
        elif array:
            fields.append(f"      {t} {field}[{size}];")
        else:
            fields.append(f"      {t} {field};")
    if not fields:
        fields.append("      uint8 structure_needs_at_least_one_member;")
    guard = f"RBSIM_IDL_{package}_{name}".upper()
    out = [f"#ifndef {guard}", f"#define {guard}"]
    out += [f'#include "{d}.idl"' for d in includes]
    out.append(f"module {package} {{ module msg {{ module dds_ {{")
    if consts:
        out.append(f"    module {name}_Constants {{")
        out.extend(consts)
        out.append("    };")
    out.append(f"    struct {name}_ {{")
    out.extend(fields)
    out.append("    };")
    out.append("}; }; };")
    out.append("#endif")
    return "\n".join(out) + "\n"


def main():
    src, dst = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    for msg in sorted(src.glob("*/msg/*.msg")):
        package, name = msg.parts[-3], msg.stem
        target = dst / package / "msg" / f"{name}.idl"
        target.parent.mkdir(parents=True, exist_ok=True)
        text = convert(package, name, msg.read_text())
        if not target.exists() or target.read_text() != text:
            target.write_text(text)


if __name__ == "__main__":
    main()
