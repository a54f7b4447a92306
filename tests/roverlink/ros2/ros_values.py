"""The values ros_api.py's reader follows through the bridge's source, and humble_api.toml as it
reads it (what each rclpy name is, the messages' fields)."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

MESSAGE_PACKAGES = ("_msgs", "_srvs", "rcl_interfaces", "builtin_interfaces")
PRIMITIVES = {"int", "float", "str", "bool", "None"}
# rclpy calls that run a callback: (index of the message or service type, index of the callback).
CALLBACKS = {
    "rclpy.node.Node.create_subscription": (0, 2),
    "rclpy.node.Node.create_service": (0, 2),
    "rclpy.node.Node.create_timer": (None, 1),
}


@dataclass(frozen=True)
class Rcl:
    """An rclpy module, class, function or object: attributes are looked up under `path`."""

    path: str
    instance: bool = False


@dataclass(frozen=True)
class Msg:
    """A message (or a service's Request/Response): `cls` for the class object."""

    name: str
    cls: bool = False


@dataclass(frozen=True)
class Srv:
    name: str


@dataclass(frozen=True)
class MsgModule:
    package: str


@dataclass(frozen=True)
class Seq:
    item: Value


@dataclass(frozen=True)
class Tup:
    items: tuple[Value, ...]


@dataclass(frozen=True)
class Own:
    """One of the bridge's modules, functions or classes (`instance`: an object of the class)."""

    key: str
    instance: bool = False


@dataclass(frozen=True)
class Bound:
    method: str
    self_value: Value


@dataclass(frozen=True)
class Super:
    cls: str


@dataclass(frozen=True)
class Union:
    options: frozenset[Value]


Value = Rcl | Msg | Srv | MsgModule | Seq | Tup | Own | Bound | Super | Union | None
"""None: not known (not followed)."""


def union(*values: Value) -> Value:
    options: set[Value] = set()
    for v in values:
        if isinstance(v, Union):
            options |= v.options
        elif v is not None:
            options.add(v)
    if not options:
        return None
    return next(iter(options)) if len(options) == 1 else Union(frozenset(options))


def options(value: Value) -> Iterator[Value]:
    if isinstance(value, Union):
        yield from value.options
    elif value is not None:
        yield value


@dataclass(frozen=True)
class Use:
    key: str
    where: str


@dataclass
class Api:
    """humble_api.toml: rclpy's names (their type, or what a call returns and the keywords it
    takes) and the messages' and services' fields."""

    rclpy: Mapping[str, Any]
    messages: Mapping[str, Mapping[str, str]]
    services: Mapping[str, Mapping[str, Mapping[str, str]]]

    def known(self) -> set[str]:
        keys = set()
        for name, entry in self.rclpy.items():
            keys.add(name)
            if isinstance(entry, dict):
                keys |= {f"{name}({kw}=)" for kw in entry.get("keywords", [])}
        for name, fields in self.message_fields().items():
            keys.add(name)
            keys |= {f"{name}.{f}" for f in fields}
        keys |= set(self.services)
        return keys

    def message_fields(self) -> dict[str, Mapping[str, str]]:
        out = dict(self.messages)
        for name, parts in self.services.items():
            out[f"{name}_Request"] = parts.get("request", {})
            out[f"{name}_Response"] = parts.get("response", {})
        return out

    def type_of(self, type_name: str) -> Value:
        """The value a field, attribute or call result of this type is."""
        base = type_name.split("[", maxsplit=1)[0]
        if not base:
            return None
        if "/" in base:
            item = Msg(base)
            return Seq(item) if "[" in type_name else item
        if base in PRIMITIVES or (base.islower() and "." not in base):
            return None  # a primitive (of the messages or of Python)
        return Rcl(type_name, instance=True)
