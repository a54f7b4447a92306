"""Helpers shared by the emitters: the DO NOT EDIT banner and literal formatting."""

from __future__ import annotations

import json
from collections.abc import Mapping

from protocol.generator.model import Spec

GENERATOR = "python -m protocol generate"


def banner(spec: Spec, comment: str) -> str:
    """Two comment lines every generated text file starts with (no dates, no absolute paths)."""
    return (
        f"{comment} DO NOT EDIT: generated from {spec.path} by `{GENERATOR}`.\n"
        f"{comment} spec hash: 0x{spec.spec_hash:08X}\n"
    )


def json_with_banner(spec: Spec, document: Mapping[str, object]) -> str:
    """`document` as indented JSON whose first line is the DO NOT EDIT banner, as a "_" key (JSON
    has no comments)."""
    head = json.dumps(f"DO NOT EDIT: generated from {spec.path} by `{GENERATOR}`. spec hash 0x{spec.spec_hash:08X}")
    return '{"_": ' + head + ",\n" + json.dumps(document, indent=2)[2:] + "\n"


def num(value: float) -> str:
    """A literal both Python and C++ read back exactly."""
    if isinstance(value, int):
        return str(value)
    if float(value).is_integer():
        return f"{value:.1f}"
    return repr(value)
