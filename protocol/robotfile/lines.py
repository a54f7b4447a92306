"""Line numbers of keys in a TOML text (tomllib reports none): for error messages only, so a
heuristic over the text that finds the usual layouts ([section] headers, key = value, inline
tables in arrays) is enough; None when the key is not written in the file."""

from __future__ import annotations

import re

_HEADER = re.compile(r"^\s*\[\[?\s*([A-Za-z0-9_.\-\" ]+?)\s*\]\]?\s*(#.*)?$")


def _span(lines: list[str], section: str) -> tuple[int, int] | None:
    """(first, end) line indexes of `section`'s body ("" = the top level, before any header)."""
    start = 0 if section == "" else None
    for i, line in enumerate(lines):
        m = _HEADER.match(line)
        if m is None:
            continue
        if start is not None:
            return start, i
        if m.group(1).replace(" ", "") == section:
            start = i + 1
    return (start, len(lines)) if start is not None else None


def line_of(text: str, section: str, path: tuple[str | int, ...] = ()) -> int | None:
    """1-based line of `path` (key, then list index / inner key...) in `section`; with no path, the
    section's header line."""
    lines = text.splitlines()
    span = _span(lines, section)
    if span is None:
        return None
    first, end = span
    if not path:
        return first if section else None
    body = "\n".join(lines[first:end])
    pos = 0
    for step in path:
        if isinstance(step, int):
            found = [m.start() for m in re.finditer(r"[{\[]", body[pos:])]
            # the list's own "[" comes first; item i starts at the (i+1)-th bracket after it
            if len(found) <= step + 1:
                return None
            pos += found[step + 1] + 1
        else:
            m = re.compile(rf"(^|[\s{{,]){re.escape(step)}\s*=", re.M).search(body, pos)
            if m is None:
                return None
            pos = m.start() + len(m.group(1))
    return first + body.count("\n", 0, pos) + 1
