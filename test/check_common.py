"""Shared by the architecture checks (check_modules.py, check_sizes.py): C++ text with comments,
literals and preprocessor lines blanked out, so that a search or a brace count sees only code
(blanked characters become spaces and newlines stay: offsets and line numbers are unchanged);
and the allow-list of known offenders, which both read.
"""
import re

_RAW_PREFIX = re.compile(r"(?:u8|u|U|L)?R$")
_IDENT = re.compile(r"[A-Za-z0-9_]")


def _blank(chars, start, end):
    for k in range(start, end):
        if chars[k] != "\n":
            chars[k] = " "


def _is_digit_separator(text, i):
    """True when the ' at i separates digits (1'000'000) rather than opening a character literal."""
    k = i
    while k > 0 and (_IDENT.match(text[k - 1]) or text[k - 1] == "'"):
        k -= 1
    return k < i and text[k].isdigit()


def strip(text, literals=True, directives=True):
    """`text` with comments blanked; with `literals`, the contents of string and character
    literals (raw strings included; the quotes stay); with `directives`, preprocessor lines."""
    chars = list(text)
    n, i, line_start = len(text), 0, True
    while i < n:
        c = text[i]
        if c == "\n":
            line_start = True
            i += 1
            continue
        if c in " \t\r\f\v":
            i += 1
            continue
        if line_start and c == "#" and directives:
            end = i
            while end < n:  # the directive with its backslash continuations
                nl = text.find("\n", end)
                if nl < 0:
                    end = n
                    break
                if text[nl - 1] == "\\":
                    end = nl + 1
                    continue
                end = nl
                break
            _blank(chars, i, end)
            i = end
            continue
        line_start = False
        if text.startswith("//", i):
            end = text.find("\n", i)
            end = n if end < 0 else end
            _blank(chars, i, end)
            i = end
        elif text.startswith("/*", i):
            end = text.find("*/", i + 2)
            end = n if end < 0 else end + 2
            _blank(chars, i, end)
            i = end
        elif c == '"':
            prefix = _RAW_PREFIX.search(text, max(0, i - 3), i)
            if prefix and (prefix.start() == 0 or not _IDENT.match(text[prefix.start() - 1])):
                open_paren = text.find("(", i)
                delim = text[i + 1 : open_paren] if open_paren >= 0 else ""
                close = text.find(")" + delim + '"', open_paren)
                end = n if open_paren < 0 or close < 0 else close + len(delim) + 2
                if literals:
                    _blank(chars, i + 1, end - 1)
                i = end
            else:
                start = i
                i = _end_of_quoted(text, i, '"')
                if literals:
                    _blank(chars, start + 1, i - 1)
        elif c == "'" and not _is_digit_separator(text, i):
            start = i
            i = _end_of_quoted(text, i, "'")
            if literals:
                _blank(chars, start + 1, i - 1)
        else:
            i += 1
    return "".join(chars)


def _end_of_quoted(text, i, quote):
    """Index past the literal opening at i (stopping at an unescaped newline, as a compiler would)."""
    k, n = i + 1, len(text)
    while k < n:
        ch = text[k]
        if ch == "\\":
            k += 2
            continue
        if ch == quote:
            return k + 1
        if ch == "\n":
            return k
        k += 1
    return n


def line_of(text, offset):
    """1-based line number of `offset` in `text`."""
    return text.count("\n", 0, offset) + 1


def line_count(text):
    """Lines as `wc -l` counts them, plus an unterminated last line."""
    return text.count("\n") + (1 if text and not text.endswith("\n") else 0)


# The kinds of entry in the allow-list of known offenders, and the fields after the kind.
ALLOWLIST_KINDS = {
    "file": ("lines", "path"),  # check_sizes.py: a source file over the line limit
    "function": ("lines", "path", "name"),  # check_sizes.py: a function over the line limit
    "mcap-reader": ("path",),  # check_modules.py: the MCAP reader API outside mcap, mcap_tools, recordings
    "mcap-framing": ("path",),  # check_modules.py: MCAP framing outside tools/mcap
}


def read_allowlist(path):
    """{kind: {key: lines or None}} from the allow-list at `path` (none: empty). Keys are the path,
    or (path, name) for functions. A line is `KIND FIELDS...`; `#` starts a comment."""
    entries = {kind: {} for kind in ALLOWLIST_KINDS}
    if not path.exists():
        return entries
    for n, raw in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        fields = raw.split("#", 1)[0].split()
        if not fields:
            continue
        spec = ALLOWLIST_KINDS.get(fields[0])
        if spec is None or len(fields) - 1 < len(spec) or (spec[-1] != "name" and len(fields) - 1 > len(spec)):
            forms = "; ".join(f"{k} {' '.join(v).upper()}" for k, v in ALLOWLIST_KINDS.items())
            raise SystemExit(f"{path}:{n}: not an allow-list entry (expected one of: {forms})")
        values = dict(zip(spec, fields[1:]))
        if "name" in spec:
            values["name"] = " ".join(fields[len(spec) :])
        lines = int(values["lines"]) if "lines" in values else None
        key = (values["path"], values["name"]) if "name" in values else values["path"]
        entries[fields[0]][key] = lines
    return entries
