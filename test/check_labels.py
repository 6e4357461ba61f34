#!/usr/bin/env python3
"""Every CTest entry carries a label naming the module it tests, and README.md's test table
(section "Tests") has one row per label with that label's test count.

    check_labels.py --ctest CTEST --build BUILD --readme README.md   # exit 1 on any mismatch
    check_labels.py ... --table                                      # print the table's counts
    check_labels.py ... --absent python=1                            # a build without one such test
"""
import argparse
import collections
import json
import re
import subprocess
import sys


def ctest_labels(ctest, build):
    out = subprocess.run([ctest, "--test-dir", build, "--show-only=json-v1"], check=True,
                         capture_output=True, text=True).stdout
    labels = {}
    for test in json.loads(out)["tests"]:
        props = {p["name"]: p["value"] for p in test.get("properties", [])}
        labels[test["name"]] = props.get("LABELS", [])
    return labels


def readme_rows(readme):
    """{label: count} from the rows "| `label` | what | count |" of the Tests section's table."""
    rows, in_tests = {}, False
    for line in open(readme, encoding="utf-8"):
        if line.startswith("## "):
            in_tests = line.strip() == "## Tests"
        m = re.match(r"^\| `([^`]+)` \|.*\| *([0-9,]+) *\|\s*$", line) if in_tests else None
        if m:
            rows[m.group(1)] = int(m.group(2).replace(",", ""))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ctest", required=True)
    ap.add_argument("--build", required=True)
    ap.add_argument("--readme", required=True)
    ap.add_argument("--table", action="store_true", help="print label counts and exit")
    ap.add_argument("--absent", action="append", default=[], metavar="LABEL=N",
                    help="N tests of LABEL that this build does not have (a build without an optional part)")
    a = ap.parse_args()

    labels = ctest_labels(a.ctest, a.build)
    counts = collections.Counter(label for ls in labels.values() for label in ls)
    if a.table:
        for label, n in sorted(counts.items()):
            print(f"{label}\t{n}")
        print(f"(all)\t{len(labels)}")
        return 0

    problems = [f"no label: {name}" for name, ls in sorted(labels.items()) if not ls]
    rows = readme_rows(a.readme)
    for item in a.absent:
        label, n = item.split("=")
        if label in rows:
            rows[label] -= int(n)
    for label in sorted(set(counts) | set(rows)):
        if label not in rows:
            problems.append(f"label {label} ({counts[label]} tests) has no row in {a.readme}'s test table")
        elif label not in counts:
            problems.append(f"{a.readme}'s test table has a row for {label}, which no test carries")
        elif rows[label] != counts[label]:
            problems.append(f"{a.readme}'s test table says {rows[label]} tests for {label}; ctest has "
                            f"{counts[label]}")
    for p in problems:
        print(p)
    print(f"{len(labels)} tests, {len(counts)} labels, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
