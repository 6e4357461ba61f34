#!/usr/bin/env python3
"""The size rules of docs/architecture.md, checked on the sources: no non-test source file over
700 lines, no function over 100 lines in sim_core/, tools/, node/ and python/.

    check_sizes.py ROOT [--allowlist FILE]   # exit 1 listing every offender

Non-test sources are the C++ (.cpp .hpp .h .c .cc and their configured .in templates), Python,
JavaScript and shell scripts (a #! line) under the source folders below; test/ and files named
*_test.* or test_* are tests. Functions are found in the C++ of sim_core/, tools/, node/ and
python/ by matching braces in code with comments, literals and preprocessor lines blanked: a
brace at namespace or class scope after a parameter list (with its qualifiers, trailing return
type or constructor initializers) opens a function, which runs to its closing brace; everything
inside (lambdas, local classes) counts as part of it. Namespace, class, enum and initializer
braces are not functions. A function's lines run from its declaration's first line to its closing
brace. The Python functions of those folders (.py files) are found by the ast module: a function
(a method as Class.name, a nested one as outer.name, also counted in its outer function) runs
from its first decorator or its def to its last line.

The allow-list (default ROOT/test/architecture_allowlist.txt) names today's offenders with their
sizes: a listed entry may shrink, not grow, and one within the limit again (or gone) must leave
the list, so the list only ever gets shorter.
"""
import argparse
import ast
import pathlib
import re
import sys

import check_common

MAX_FILE_LINES = 700
MAX_FUNCTION_LINES = 100
SOURCE_FOLDERS = ("sim_core", "tools", "node", "python", "bench", "examples", "scripts")
FUNCTION_FOLDERS = ("sim_core", "tools", "node", "python")
CPP_SUFFIXES = (".cpp", ".hpp", ".h", ".c", ".cc")
OTHER_SUFFIXES = (".py", ".js")
SKIPPED_DIRS = ("test", "node_modules", "__pycache__")

_QUALIFIERS = re.compile(r"\s*(?:\bconst|\bnoexcept|\boverride|\bfinal|\bmutable|\bvolatile|\btry|&&|&)\s*$")
_ACCESS = re.compile(r"^\s*(?:public|private|protected)\s*:(?!:)")
_CLASS_KEY = re.compile(r"\b(?:class|struct|union|enum)\b")
_CTOR_INIT = re.compile(r"\)\s*(?:noexcept\s*)?:(?!:)")
_NAME_BEFORE = re.compile(r"((?:[A-Za-z_]\w*\s*(?:<[^<>()]*>)?\s*::\s*)*~?[A-Za-z_]\w*)\s*$")
_OPERATOR = re.compile(r"((?:[A-Za-z_]\w*\s*(?:<[^<>()]*>)?\s*::\s*)*operator\s*(?:\(\s*\)|\[\s*\]|[^\s\w(]+|[A-Za-z_][\w\s:<>*&]*?))\s*\(")
_NOT_NAMES = {"decltype", "noexcept", "alignas", "sizeof", "requires", "throw", "__attribute__", "static_assert"}


def is_test(rel):
    name = rel.name
    return rel.parts[0] == "test" or re.search(r"_test\.[A-Za-z.]+$", name) or name.startswith("test_")


def source_files(root):
    """(relative path, is C++) of every non-test source file."""
    for folder in SOURCE_FOLDERS:
        base = root / folder
        if not base.is_dir():
            continue
        for path in sorted(base.rglob("*")):
            rel = path.relative_to(root)
            if not path.is_file() or any(p in SKIPPED_DIRS or p.startswith((".", "build")) for p in rel.parts[:-1]):
                continue
            if is_test(rel):
                continue
            suffix = path.suffix if path.suffix != ".in" else pathlib.Path(path.stem).suffix
            if suffix in CPP_SUFFIXES:
                yield rel, True
            elif suffix in OTHER_SUFFIXES or (path.suffix == "" and _has_shebang(path)):
                yield rel, False


def _has_shebang(path):
    with open(path, "rb") as f:
        return f.read(2) == b"#!"


def _strip_template_prefix(head):
    """`head` without leading `template <...>` clauses."""
    while True:
        m = re.match(r"\s*template\s*<", head)
        if not m:
            return head
        depth, k = 1, m.end()
        while k < len(head) and depth:
            depth += {"<": 1, ">": -1}.get(head[k], 0)
            k += 1
        head = head[k:]


def _top_level(head):
    """`head` with everything inside (), [] and <> blanked (for keyword searches)."""
    out, depth = [], 0
    for ch in head:
        if ch in "([":
            depth += 1
        elif ch in ")]" and depth:
            depth -= 1
            out.append(ch)
            continue
        out.append(ch if depth == 0 else " ")
    return "".join(out)


def _ends_like_lambda(head):
    """`[captures]` at the end of `head`, where a lambda may start (not an array's size)."""
    depth, k = 0, len(head) - 1
    while k >= 0:
        depth += {"]": 1, "[": -1}.get(head[k], 0)
        if depth == 0:
            break
        k -= 1
    before = head[:k].rstrip()
    return not before or before[-1] in "=(,{" or before.endswith("return")


def _function_head(head):
    """True when a brace after `head` (at namespace or class scope) opens a function body."""
    if _CTOR_INIT.search(head) and head.endswith(("}", ")")):
        return True
    if re.search(r"\)[\s\w&]*->", head):
        return True
    t = head
    while True:
        stripped = _QUALIFIERS.sub("", t)
        if stripped == t:
            break
        t = stripped
    if t.endswith(")"):
        return True
    return t.endswith("]") and _ends_like_lambda(t)


def _function_name(head):
    m = _OPERATOR.search(head)
    if m:
        return re.sub(r"\s+", "", m.group(1)) if "(" in m.group(1) else re.sub(r"\s+", " ", m.group(1))
    depth = 0
    for k, ch in enumerate(head):
        if ch == "(":
            if depth == 0:
                before = head[:k].rstrip()
                if before.endswith("]"):
                    return "lambda"
                name = _NAME_BEFORE.search(before)
                if name and name.group(1).split("::")[-1].strip() not in _NOT_NAMES:
                    return re.sub(r"\s+", "", name.group(1))
            depth += 1
        elif ch == ")":
            depth -= 1
    return "lambda" if head.rstrip().endswith("]") else "?"


def classify(head):
    """'scope' (namespace, class, enum, extern), 'function' or 'init' for a brace after `head`."""
    h = head.strip()
    while _ACCESS.match(h):
        h = _ACCESS.sub("", h, count=1).strip()
    h = _strip_template_prefix(h).strip()
    if re.match(r"(?:inline\s+)?namespace\b", h) or re.match(r'extern\s*"', h):
        return "scope"
    if not h or h.endswith(("=", ",", "(", "{", "return")):
        return "init"
    if _function_head(h):
        return "function"
    if _CLASS_KEY.search(_top_level(h)):
        return "scope"
    return "init"


def functions(text):
    """(name, first line, line count) of every function definition in C++ `text`."""
    code = check_common.strip(text)
    # stack: (kind, (declaration start, head), parentheses open outside the brace)
    found, stack, stmt_start, parens, depth = [], [], 0, 0, 0
    for i, ch in enumerate(code):
        if depth:  # inside a function (or a brace within parentheses) everything is part of it
            if ch == "{":
                depth += 1
            elif ch == "}":
                depth -= 1
                if depth == 0:
                    kind, (start, head), parens = stack.pop()
                    if kind == "function":
                        first, last = check_common.line_of(code, start), check_common.line_of(code, i)
                        name = _function_name(_strip_template_prefix(head.strip()))
                        found.append((name, first, last - first + 1))
                        if not (stack and stack[-1][0] == "init"):
                            stmt_start = i + 1
            continue
        in_init = bool(stack) and stack[-1][0] == "init"
        if ch == "(":
            parens += 1
        elif ch == ")":
            parens = max(0, parens - 1)
        elif ch == ";" and not in_init and parens == 0:
            stmt_start = i + 1
        elif ch == "{":
            head = code[stmt_start:i]
            # a brace inside parentheses (a lambda or braced argument in a constructor's
            # initializers, a static_assert) belongs to the declaration around it
            kind = "opaque" if parens else classify(head)
            if in_init and kind == "scope":
                kind = "init"
            stripped = head.strip()
            while _ACCESS.match(stripped):  # the declaration starts after `public:`
                stripped = _ACCESS.sub("", stripped, count=1).strip()
            start = code.index(stripped, stmt_start) if stripped else i
            stack.append((kind, (start, head), parens))
            parens = 0
            if kind in ("function", "opaque"):
                depth = 1
            elif kind == "scope" and not in_init:
                stmt_start = i + 1
        elif ch == "}" and stack:
            kind, _, parens = stack.pop()
            if kind == "scope" and not (stack and stack[-1][0] == "init"):
                stmt_start = i + 1
    return found


def python_functions(text):
    """(name, first line, line count) of every function definition in Python `text`."""
    found = []

    def walk(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                first = min([child.lineno] + [d.lineno for d in child.decorator_list])
                found.append((prefix + child.name, first, child.end_lineno - first + 1))
                walk(child, prefix + child.name + ".")
            elif isinstance(child, ast.ClassDef):
                walk(child, prefix + child.name + ".")
            else:
                walk(child, prefix)

    walk(ast.parse(text), "")
    return found


def function_sizes(rel, is_cpp, text):
    """(name, first line, line count) of the functions of a source file the function rule covers."""
    if rel.parts[0] not in FUNCTION_FOLDERS:
        return []
    if is_cpp:
        return functions(text)
    if rel.suffix == ".py":
        try:
            return python_functions(text)
        except SyntaxError as e:  # fails the check, as a function over the limit would, naming why
            return [(f"<unparsable: {e.msg}>", e.lineno or 1, MAX_FUNCTION_LINES + 1)]
    return []


def check(root, allowlist):
    listed = check_common.read_allowlist(allowlist)
    listed_files, listed_funcs = listed["file"], listed["function"]
    problems, notes = [], []
    sizes, longest, nfuncs = {}, {}, 0  # path -> lines; (path, name) -> (lines, line)
    for rel, is_cpp in source_files(root):
        text = (root / rel).read_text(encoding="utf-8", errors="replace")
        path = rel.as_posix()
        sizes[path] = check_common.line_count(text)
        for name, line, count in function_sizes(rel, is_cpp, text):
            nfuncs += 1
            if count > longest.get((path, name), (0, 0))[0]:
                longest[(path, name)] = (count, line)

    for path, lines in sizes.items():
        if lines <= MAX_FILE_LINES:
            continue
        allowed = listed_files.get(path)
        if allowed is None:
            problems.append(f"{path}:1: file is {lines} lines (limit {MAX_FILE_LINES})")
        elif lines > allowed:
            problems.append(f"{path}:1: file is {lines} lines (limit {MAX_FILE_LINES}; allow-listed at {allowed}, "
                            "which may only shrink)")
        elif lines < allowed:
            notes.append(f"{path}: file shrank to {lines} lines: lower its allow-list entry ({allowed})")
    for (path, name), (lines, line) in sorted(longest.items()):
        if lines <= MAX_FUNCTION_LINES:
            continue
        allowed = listed_funcs.get((path, name))
        if allowed is None:
            problems.append(f"{path}:{line}: function {name} is {lines} lines (limit {MAX_FUNCTION_LINES})")
        elif lines > allowed:
            problems.append(f"{path}:{line}: function {name} is {lines} lines (limit {MAX_FUNCTION_LINES}; "
                            f"allow-listed at {allowed}, which may only shrink)")
        elif lines < allowed:
            notes.append(f"{path}:{line}: function {name} shrank to {lines} lines: lower its allow-list entry "
                         f"({allowed})")
    for path in sorted(listed_files):
        if sizes.get(path, 0) <= MAX_FILE_LINES:
            now = "no longer exists" if path not in sizes else f"is {sizes[path]} lines (limit {MAX_FILE_LINES})"
            problems.append(f"{allowlist}: file {path} {now}: its entry can be removed")
    for path, name in sorted(listed_funcs):
        lines = longest.get((path, name), (None, 0))[0]
        if lines is None or lines <= MAX_FUNCTION_LINES:
            now = "no longer exists" if lines is None else f"is {lines} lines (limit {MAX_FUNCTION_LINES})"
            problems.append(f"{allowlist}: function {name} of {path} {now}: its entry can be removed")
    return problems, notes, len(sizes), nfuncs


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("root", type=pathlib.Path)
    ap.add_argument("--allowlist", type=pathlib.Path, help="default: ROOT/test/architecture_allowlist.txt")
    ap.add_argument("--list", action="store_true", help="print every file and function over its limit")
    a = ap.parse_args()
    root = a.root.resolve()
    allowlist = a.allowlist or root / "test" / "architecture_allowlist.txt"
    if a.list:
        for rel, is_cpp in source_files(root):
            text = (root / rel).read_text(encoding="utf-8", errors="replace")
            if check_common.line_count(text) > MAX_FILE_LINES:
                print(f"file {check_common.line_count(text)} {rel.as_posix()}")
            for name, _line, count in function_sizes(rel, is_cpp, text):
                if count > MAX_FUNCTION_LINES:
                    print(f"function {count} {rel.as_posix()} {name}")
        return 0
    problems, notes, nfiles, nfuncs = check(root, allowlist)
    for p in problems + notes:
        print(p)
    if nfiles == 0:
        problems.append("no source files found: wrong ROOT?")
        print(problems[-1])
    print(f"{nfiles} source files, {nfuncs} functions, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
