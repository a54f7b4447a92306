"""The hardware contract (protocol/spec/hardware.toml): the enums the firmware core hands to a board."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from protocol.generator.loader import SpecError, _Loader
from protocol.generator.model import Enum, Spec
from protocol.toml import tomllib


@dataclass(frozen=True)
class Hardware:
    path: str  # repository-relative, for DO NOT EDIT lines
    enums: tuple[Enum, ...]


def parse(text: str, path: str, spec: Spec) -> Hardware:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(path, "", f"not valid TOML: {exc}") from None
    loader = _Loader(path, data)
    top = loader.keys(data, "top level", {"enums"}, set())
    enums = loader.enums(top["enums"])
    # The emulator and the tests import these next to the spec's enums: one name, one meaning.
    taken = {e.name for e in spec.enums} | {m.class_name for m in spec.messages}
    for i, e in enumerate(enums):
        if e.name in taken:
            raise SpecError(path, f"enums[{i}] {e.name}", f"{e.name!r} is already a name in {spec.path}")
    return Hardware(path, enums)


def load(path: Path, root: Path, spec: Spec) -> Hardware:
    return parse(path.read_text(encoding="utf-8"), path.resolve().relative_to(root.resolve()).as_posix(), spec)
