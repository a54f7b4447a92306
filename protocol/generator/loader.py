"""Load and validate the spec file into the model.

Every problem raises SpecError naming the file, the entry (e.g. `messages[3] HELLO > fields[1]
spec_hash`) and what is wrong, so a spec author never has to read a traceback.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

from protocol.generator import hashing
from protocol.generator.model import (
    CAMEL,
    DELIVERY_CLASSES,
    DIRECTIONS,
    PRIMITIVES,
    SNAKE,
    UPPER,
    Constant,
    Enum,
    EnumValue,
    Field,
    FieldSet,
    Message,
    Named,
    Spec,
    StateMachine,
    Transition,
    release_parts,
)
from protocol.generator.reserved import reserved_reason
from protocol.toml import tomllib


class SpecError(Exception):
    """The spec file is invalid. str() is a one-line, human-readable diagnosis."""

    def __init__(self, path: str, entry: str, problem: str) -> None:
        self.path = path
        self.entry = entry
        self.problem = problem
        where = f"{path}: {entry}: " if entry else f"{path}: "
        super().__init__(where + problem)


_TYPE = re.compile(r"^(?P<base>[A-Za-z][A-Za-z0-9]*)(?:\[(?P<var>\.\.)?(?P<n>[0-9]+)\])?$")


class _Loader:
    def __init__(self, path: str, data: dict[str, Any]) -> None:
        self.path = path
        self.data = data
        self.constant_values: dict[str, int] = {}  # for min/max written as a constant's name

    def fail(self, entry: str, problem: str) -> SpecError:
        return SpecError(self.path, entry, problem)

    def keys(self, table: Any, entry: str, required: set[str], optional: set[str]) -> dict[str, Any]:
        if not isinstance(table, dict):
            raise self.fail(entry, f"expected a table, got {type(table).__name__}")
        missing = sorted(required - table.keys())
        if missing:
            raise self.fail(entry, f"missing key(s): {', '.join(missing)}")
        unknown = sorted(table.keys() - required - optional)
        if unknown:
            raise self.fail(
                entry, f"unknown key(s): {', '.join(unknown)} (allowed: {', '.join(sorted(required | optional))})"
            )
        return table

    def typed(self, value: Any, kind: type | tuple[type, ...], entry: str, key: str) -> Any:
        if isinstance(value, bool) or not isinstance(value, kind):
            names = kind.__name__ if isinstance(kind, type) else " or ".join(k.__name__ for k in kind)
            raise self.fail(entry, f"'{key}' must be {names}, got {value!r}")
        return value

    def name(self, value: Any, pattern: re.Pattern[str], entry: str, style: str) -> str:
        self.typed(value, str, entry, "name")
        if not pattern.match(value):
            raise self.fail(entry, f"name {value!r} must be {style}")
        why = reserved_reason(value)
        if why:
            raise self.fail(entry, f"name {value!r} is reserved ({why})")
        return str(value)

    def unique(self, items: list[Any], key: Callable[[Any], Any], what: str, section: str) -> None:
        seen: dict[Any, int] = {}
        for i, item in enumerate(items):
            k = key(item)
            if k in seen:
                raise self.fail(f"{section}[{i}]", f"duplicate {what} {k!r} (first used by {section}[{seen[k]}])")
            seen[k] = i

    # -- sections -------------------------------------------------------------------------------
    def load(self) -> Spec:
        top = self.keys(
            self.data,
            "top level",
            {"protocol", "release", "crc", "constants", "enums", "messages", "state_machine"},
            {"field_sets"},
        )
        release = self.release(top["release"])
        proto = self.keys(top["protocol"], "protocol", {"name", "version", "max_payload"}, {"doc"})
        version = self.typed(proto["version"], int, "protocol", "version")
        if not 0 < version <= 0xFF:
            raise self.fail("protocol", f"version {version} does not fit u8 (1..255)")
        max_payload = self.typed(proto["max_payload"], int, "protocol", "max_payload")
        if not 0 < max_payload <= 250:
            raise self.fail(
                "protocol", f"max_payload {max_payload} must be 1..250 (a frame must stay below one COBS block)"
            )
        crc = self.keys(top["crc"], "crc", {"name", "poly", "init", "xorout", "check"}, set())
        for k in ("poly", "init", "xorout", "check"):
            self.typed(crc[k], int, "crc", k)
        if hashing.crc16(b"123456789", crc["init"], crc["poly"]) ^ crc["xorout"] != crc["check"]:
            raise self.fail("crc", "check value does not match poly/init/xorout over b'123456789'")
        if (crc["poly"], crc["init"], crc["xorout"]) != (0x1021, 0xFFFF, 0):
            raise self.fail(
                "crc", "only CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, xorout 0) is implemented by the codecs"
            )

        constants = self.constants(top["constants"])
        self.constant_values = {c.name: c.value for c in constants}
        enums = self.enums(top["enums"])
        field_sets = self.field_sets(top.get("field_sets", []), enums)
        messages = self.messages(top["messages"], enums, field_sets, max_payload)
        sm = self.state_machine(top["state_machine"])
        self.cross_names(constants, enums, messages, field_sets)

        canonical = {
            "protocol": {"name": proto["name"], "version": version, "max_payload": max_payload},
            "crc": {k: crc[k] for k in ("poly", "init", "xorout")},
            "constants": [[c.name, c.type, c.value] for c in constants],
            "enums": [[e.name, e.base, e.flags, [[v.name, v.value] for v in e.values]] for e in enums],
            "messages": [
                [
                    m.id,
                    m.name,
                    m.direction,
                    m.delivery,
                    m.crc_extra,
                    [[f.name, f.type_text, f.min, f.max] for f in m.fields],
                ]
                for m in messages
            ],
            "state_machine": {
                "initial": sm.initial,
                "rows": [[*r[:5], list(r[5])] for r in sm.rows()],
            },
        }
        return Spec(
            path=self.path,
            name=self.typed(proto["name"], str, "protocol", "name"),
            version=version,
            max_payload=max_payload,
            crc_name=str(crc["name"]),
            crc_poly=crc["poly"],
            crc_init=crc["init"],
            crc_xorout=crc["xorout"],
            crc_check=crc["check"],
            constants=constants,
            enums=enums,
            messages=messages,
            state_machine=sm,
            spec_hash=hashing.spec_hash(canonical),
            doc=str(proto.get("doc", "")),
            field_sets=field_sets,
            release=release,
        )

    def release(self, raw: Any) -> tuple[int, int, int]:
        """[release] version = "MAJOR.MINOR.PATCH", each part 0..255 (IDENTITY carries it as u8[3])."""
        text = self.typed(self.keys(raw, "release", {"version"}, {"doc"})["version"], str, "release", "version")
        if (parts := release_parts(text)) is None:
            raise self.fail("release", f"version {text!r} must be MAJOR.MINOR.PATCH, each 0..255 without leading zeros")
        return parts

    def constants(self, raw: Any) -> tuple[Constant, ...]:
        out = []
        for i, c in enumerate(self.typed(raw, list, "constants", "constants")):
            entry = f"constants[{i}]"
            c = self.keys(c, entry, {"name", "type", "value", "doc"}, set())
            name = self.name(c["name"], UPPER, entry, "UPPER_SNAKE_CASE")
            entry = f"constants[{i}] {name}"
            if c["type"] not in PRIMITIVES or c["type"] in ("f32", "char"):
                raise self.fail(entry, f"unknown type {c['type']!r} (constants are integers: u8 i8 u16 i16 u32 i32)")
            value = self.typed(c["value"], int, entry, "value")
            _, _, _, lo, hi = PRIMITIVES[c["type"]]
            assert lo is not None and hi is not None
            if not lo <= value <= hi:
                raise self.fail(entry, f"value {value} does not fit {c['type']} ({lo}..{hi})")
            out.append(Constant(name, c["type"], value, str(c["doc"])))
        self.unique(out, lambda c: c.name, "constant name", "constants")
        return tuple(out)

    def enums(self, raw: Any) -> tuple[Enum, ...]:
        out = []
        for i, e in enumerate(self.typed(raw, list, "enums", "enums")):
            entry = f"enums[{i}]"
            e = self.keys(e, entry, {"name", "base", "values", "doc"}, {"flags"})
            name = self.name(e["name"], CAMEL, entry, "CamelCase")
            entry = f"enums[{i}] {name}"
            base = e["base"]
            if base not in ("u8", "u16", "u32"):
                raise self.fail(entry, f"base {base!r} must be an unsigned type (u8, u16, u32)")
            flags = bool(e.get("flags", False))
            hi = PRIMITIVES[base][4]
            values = []
            for j, v in enumerate(self.typed(e["values"], list, entry, "values")):
                ventry = f"{entry} > values[{j}]"
                v = self.keys(v, ventry, {"name", "value", "doc"}, set())
                vname = self.name(v["name"], UPPER, ventry, "UPPER_SNAKE_CASE")
                ventry = f"{entry} > values[{j}] {vname}"
                value = self.typed(v["value"], int, ventry, "value")
                if not 0 <= value <= (hi or 0):
                    raise self.fail(ventry, f"value {value} does not fit the base type {base} (0..{hi})")
                if flags and (value == 0 or value & (value - 1)):
                    raise self.fail(ventry, f"flag value {value:#x} must be a single bit")
                values.append(EnumValue(vname, value, str(v["doc"])))
            if not values:
                raise self.fail(entry, "an enum needs at least one value")
            self.unique(values, lambda v: v.name, "value name", f"{entry} > values")
            self.unique(values, lambda v: v.value, "value", f"{entry} > values")
            out.append(Enum(name, base, flags, tuple(values), str(e["doc"])))
        self.unique(out, lambda e: e.name, "enum name", "enums")
        return tuple(out)

    def field_sets(self, raw: Any, enums: tuple[Enum, ...]) -> tuple[FieldSet, ...]:
        out: list[FieldSet] = []
        for i, s in enumerate(self.typed(raw, list, "field_sets", "field_sets")):
            entry = f"field_sets[{i}]"
            s = self.keys(s, entry, {"name", "fields"}, {"doc", "struct"})
            name = self.name(s["name"], SNAKE, entry, "snake_case")
            if any(f.name == name for f in out):
                raise self.fail(entry, f"duplicate field set name {name!r}")
            entry = f"field_sets[{i}] {name}"
            raw_fields = self.typed(s["fields"], list, entry, "fields")
            fields = tuple(self.field(f, f"{entry} > fields[{j}]", enums) for j, f in enumerate(raw_fields))
            self.unique(list(fields), lambda f: f.name, "field name", f"{entry} > fields")
            struct = s.get("struct")
            if struct is not None:
                struct = self.name(struct, CAMEL, entry, "CamelCase")
                for f in fields:
                    if f.enum is not None or f.is_float or f.count is not None or f.max_len is not None:
                        raise self.fail(f"{entry} > {f.name}", "a struct field set holds scalar integer fields only")
            out.append(FieldSet(name, struct, fields, str(s.get("doc", ""))))
        return tuple(out)

    def field(self, raw: Any, entry: str, enums: tuple[Enum, ...]) -> Field:
        f = self.keys(raw, entry, {"name", "type", "doc"}, {"min", "max", "unit"})
        name = self.name(f["name"], SNAKE, entry, "snake_case")
        entry = f"{entry} {name}"
        type_text = self.typed(f["type"], str, entry, "type")
        m = _TYPE.match(type_text)
        if not m:
            raise self.fail(entry, f"unknown type {type_text!r}")
        base = m.group("base")
        enum = next((e for e in enums if e.name == base), None)
        if enum is None and base not in PRIMITIVES:
            known = ", ".join(list(PRIMITIVES) + [e.name for e in enums])
            raise self.fail(entry, f"unknown type {base!r} (known: {known})")
        prim = enum.base if enum else base
        count = max_len = None
        if m.group("n") is not None:
            n = int(m.group("n"))
            if n < 1:
                raise self.fail(entry, f"array length must be at least 1, got {n}")
            if m.group("var"):
                if base not in ("u8", "char"):
                    raise self.fail(entry, "only u8 and char arrays can have a variable length")
                max_len = n
            else:
                count = n
            if enum is not None:
                raise self.fail(entry, "arrays of enums or flags are not supported")
        elif base == "char":
            raise self.fail(entry, "char is only allowed as a variable-length array, e.g. char[..16]")
        lo = self.bound(f.get("min"), entry, "min")
        hi = self.bound(f.get("max"), entry, "max")
        if (lo is not None or hi is not None) and (enum is not None or base == "char" or max_len is not None):
            raise self.fail(entry, "min/max apply to numeric fields only")
        _, _, _, tlo, thi = PRIMITIVES[prim]
        for key, val in (("min", lo), ("max", hi)):
            if val is None:
                continue
            self.typed(val, (int, float), entry, key)
            if prim != "f32" and not isinstance(val, int):
                raise self.fail(entry, f"{key} {val!r} must be an integer for {prim}")
            if tlo is not None and thi is not None and not tlo <= val <= thi:
                raise self.fail(entry, f"{key} {val} does not fit {prim} ({tlo}..{thi})")
        if lo is not None and hi is not None and lo > hi:
            raise self.fail(entry, f"min {lo} is greater than max {hi}")
        return Field(
            name=name,
            prim=prim,
            enum=enum,
            count=count,
            max_len=max_len,
            min=lo,
            max=hi,
            unit=str(f.get("unit", "")),
            doc=str(f["doc"]),
        )

    def bound(self, value: Any, entry: str, key: str) -> Any:
        """A field's min or max: a number, or the name of a constant (written once, used twice)."""
        if not isinstance(value, str):
            return value
        if value not in self.constant_values:
            known = ", ".join(self.constant_values) or "none"
            raise self.fail(entry, f"{key} {value!r} is not a constant (constants: {known})")
        return self.constant_values[value]

    def messages(
        self, raw: Any, enums: tuple[Enum, ...], field_sets: tuple[FieldSet, ...], max_payload: int
    ) -> tuple[Message, ...]:
        sets = {s.name: s for s in field_sets}
        out = []
        for i, m in enumerate(self.typed(raw, list, "messages", "messages")):
            entry = f"messages[{i}]"
            m = self.keys(m, entry, {"id", "name", "direction", "delivery", "fields", "doc"}, set())
            name = self.name(m["name"], UPPER, entry, "UPPER_SNAKE_CASE")
            entry = f"messages[{i}] {name}"
            msg_id = self.typed(m["id"], int, entry, "id")
            if not 0 <= msg_id <= 0xFF:
                raise self.fail(entry, f"id {msg_id} does not fit u8 (0..255)")
            direction = m["direction"]
            if direction not in DIRECTIONS:
                raise self.fail(entry, f"direction {direction!r} must be one of {', '.join(DIRECTIONS)}")
            if (direction == "host_to_mcu") != (msg_id < 0x80):
                raise self.fail(
                    entry, f"id {msg_id:#04x}: host_to_mcu ids are below 0x80, mcu_to_host ids 0x80 and above"
                )
            if m["delivery"] not in DELIVERY_CLASSES:
                raise self.fail(entry, f"delivery {m['delivery']!r} must be one of {', '.join(DELIVERY_CLASSES)}")
            if direction == "mcu_to_host" and m["delivery"] == "setpoint":
                raise self.fail(entry, "setpoints go from host to MCU")
            where: list[str] = []
            fields_in: list[Field] = []
            includes: list[str] = []
            for j, f in enumerate(self.typed(m["fields"], list, entry, "fields")):
                if isinstance(f, dict) and "include" in f:
                    self.keys(f, f"{entry} > fields[{j}]", {"include"}, set())
                    if f["include"] not in sets:
                        raise self.fail(f"{entry} > fields[{j}]", f"unknown field set {f['include']!r}")
                    included = sets[f["include"]]
                    includes.append(included.name)
                    for k, g in enumerate(included.fields):
                        where.append(f"{entry} > fields[{j}] (field set {included.name}[{k}])")
                        fields_in.append(g)
                else:
                    where.append(f"{entry} > fields[{j}]")
                    fields_in.append(self.field(f, where[-1], enums))
            fields = tuple(fields_in)
            self.unique(list(fields), lambda f: f.name, "field name", f"{entry} > fields")
            for fe, fe_f in zip(where[:-1], fields[:-1], strict=True):
                if fe_f.max_len is not None:
                    raise self.fail(f"{fe} {fe_f.name}", "a variable-length array must be the last field")
            sig = hashing.signature(
                name, [((f"{f.prim}:{f.enum.name}" if f.enum else f.prim) + _suffix(f), f.name) for f in fields]
            )
            msg = Message(
                msg_id, name, direction, m["delivery"], fields, str(m["doc"]), hashing.crc_extra(sig), tuple(includes)
            )
            if msg.payload_max > max_payload:
                raise self.fail(entry, f"payload of up to {msg.payload_max} bytes exceeds max_payload {max_payload}")
            out.append(msg)
        self.unique(out, lambda m: m.id, "message id", "messages")
        self.unique(out, lambda m: m.name, "message name", "messages")
        self.unique(out, lambda m: m.class_name, "message class name", "messages")
        return tuple(out)

    def named(self, raw: Any, section: str, pattern: re.Pattern[str], style: str) -> tuple[Named, ...]:
        out = []
        for i, n in enumerate(self.typed(raw, list, section, section.rsplit(".", 1)[-1])):
            entry = f"{section}[{i}]"
            n = self.keys(n, entry, {"name", "doc"}, set())
            out.append(Named(self.name(n["name"], pattern, entry, style), str(n["doc"])))
        self.unique(out, lambda n: n.name, "name", section)
        return tuple(out)

    def state_machine(self, raw: Any) -> StateMachine:
        sec = "state_machine"
        sm = self.keys(raw, sec, {"initial", "states", "events", "guards", "actions", "transitions"}, {"doc"})
        states = self.named(sm["states"], f"{sec}.states", UPPER, "UPPER_SNAKE_CASE")
        events = self.named(sm["events"], f"{sec}.events", UPPER, "UPPER_SNAKE_CASE")
        guards = self.named(sm["guards"], f"{sec}.guards", SNAKE, "snake_case")
        actions = self.named(sm["actions"], f"{sec}.actions", SNAKE, "snake_case")
        state_names = [s.name for s in states]
        if self.typed(sm["initial"], str, sec, "initial") not in state_names:
            raise self.fail(sec, f"initial state {sm['initial']!r} is not a declared state")
        transitions = []
        for i, t in enumerate(self.typed(sm["transitions"], list, sec, "transitions")):
            entry = f"{sec}.transitions[{i}]"
            t = self.keys(t, entry, {"from", "event", "actions"}, {"to", "guard"})
            sources = [self.typed(s, str, entry, "from") for s in self.typed(t["from"], list, entry, "from")]
            if sources == ["*"]:
                sources = state_names
            for s in sources:
                if s not in state_names:
                    raise self.fail(entry, f"unknown state {s!r} in 'from' (states: {', '.join(state_names)})")
            target = None if t.get("to") is None else self.typed(t["to"], str, entry, "to")
            if target is not None and target not in state_names:
                raise self.fail(entry, f"unknown state {target!r} in 'to'")
            if self.typed(t["event"], str, entry, "event") not in [e.name for e in events]:
                raise self.fail(entry, f"unknown event {t['event']!r}")
            guard = None if t.get("guard") is None else self.typed(t["guard"], str, entry, "guard")
            negated = False
            if guard is not None:
                negated = guard.startswith("!")
                guard = guard.lstrip("!")
                if guard not in [g.name for g in guards]:
                    raise self.fail(entry, f"unknown guard {guard!r}")
            for a in self.typed(t["actions"], list, entry, "actions"):
                if self.typed(a, str, entry, "actions") not in [x.name for x in actions]:
                    raise self.fail(entry, f"unknown action {a!r}")
            transitions.append(Transition(tuple(sources), t["event"], guard, negated, target, tuple(t["actions"])))
        machine = StateMachine(
            sm["initial"], states, events, guards, actions, tuple(transitions), str(sm.get("doc", ""))
        )
        self.check_machine(machine)
        return machine

    def check_machine(self, sm: StateMachine) -> None:
        sec = "state_machine"
        rows = sm.rows()
        seen: dict[tuple[str, str], list[tuple[str | None, bool]]] = {}
        for src, event, guard, negated, _to, _acts in rows:
            prior = seen.setdefault((src, event), [])
            if (None, False) in prior:
                raise self.fail(sec, f"state {src} event {event}: a row after an unguarded row can never fire")
            if (guard, negated) in prior:
                raise self.fail(sec, f"state {src} event {event}: two rows with the same guard")
            prior.append((guard, negated))
        for e in sm.events:
            if not any(r[1] == e.name for r in rows):
                raise self.fail(f"{sec}.events", f"event {e.name} has no transition")
        for kind, names, used in (
            ("guard", sm.guards, {r[2] for r in rows}),
            ("action", sm.actions, {a for r in rows for a in r[5]}),
        ):
            for n in names:
                if n.name not in used:
                    raise self.fail(f"{sec}.{kind}s", f"{kind} {n.name} is never used")
        reachable = {sm.initial}
        frontier = [sm.initial]
        while frontier:
            s = frontier.pop()
            for src, _e, _g, _n, to, _a in rows:
                if src == s and to not in reachable:
                    reachable.add(to)
                    frontier.append(to)
        for state in sm.states:
            if state.name not in reachable:
                raise self.fail(f"{sec}.states", f"state {state.name} is unreachable from {sm.initial}")

    def cross_names(
        self,
        constants: tuple[Constant, ...],
        enums: tuple[Enum, ...],
        messages: tuple[Message, ...],
        field_sets: tuple[FieldSet, ...],
    ) -> None:
        """Python and C++ share one namespace per module: an enum and a message class may not collide."""
        owners: dict[str, str] = {}
        for kind, names in (
            ("constant", [c.name for c in constants]),
            ("enum", [e.name for e in enums]),
            ("message class", [m.class_name for m in messages]),
            ("field set struct", [s.struct for s in field_sets if s.struct is not None]),
            ("field set name tuple", [s.name.upper() for s in field_sets if s.struct is not None]),
        ):
            for n in names:
                if n in owners:
                    raise self.fail("top level", f"{kind} {n!r} collides with {owners[n]} of the same name")
                owners[n] = f"a {kind}"


def _suffix(f: Field) -> str:
    if f.count is not None:
        return f"[{f.count}]"
    if f.max_len is not None:
        return f"[..{f.max_len}]"
    return ""


def parse(text: str, path: str) -> Spec:
    """Validate TOML text; `path` is what errors and DO NOT EDIT lines call the file."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(path, "", f"not valid TOML: {exc}") from None
    return _Loader(path, data).load()


def load(path: Path, root: Path) -> Spec:
    return parse(path.read_text(encoding="utf-8"), path.resolve().relative_to(root.resolve()).as_posix())
