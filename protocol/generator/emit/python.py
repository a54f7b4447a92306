"""Emit protocol/generated/: constants, enums, messages, state machine table, construct oracle."""

from __future__ import annotations

from protocol.generator.emit.common import banner, num
from protocol.generator.model import PRIMITIVES, Enum, Field, Message, Spec

PKG = "protocol/generated"


def emit(spec: Spec) -> dict[str, str]:
    return {
        f"{PKG}/__init__.py": _init(spec),
        f"{PKG}/constants.py": _constants(spec),
        f"{PKG}/enums.py": _enums(spec),
        f"{PKG}/messages.py": _messages(spec),
        f"{PKG}/state_machine.py": _state_machine(spec),
        f"{PKG}/oracle.py": _oracle(spec),
        f"{PKG}/structs.py": _structs(spec),
    }


def doc(text: str, indent: str = "") -> str:
    text = text.replace("\\", "\\\\").replace('"""', '\\"\\"\\"')
    return f'{indent}"""{text}"""\n'


def _init(spec: Spec) -> str:
    return banner(spec, "#") + doc(
        "Code generated from the RoverLink spec: constants, enums, messages, the session table, the construct oracle."
    )


def _constants(spec: Spec) -> str:
    out = [banner(spec, "#"), doc("Protocol constants."), "\nfrom typing import Final\n\n"]
    out.append(f"PROTOCOL_VERSION: Final = {spec.version}\n")
    out.append(f"SPEC_HASH: Final = 0x{spec.spec_hash:08X}\n")
    out.append(f"MAX_PAYLOAD: Final = {spec.max_payload}\n")
    out.append(f"MAX_BODY: Final = {spec.max_body}\n")
    out.append('"""Longest decoded frame: msg_id, seq, payload, CRC."""\n')
    out.append(f"MAX_FRAME: Final = {spec.max_frame}\n")
    out.append('"""Longest frame on the wire, delimiter included."""\n')
    for c in spec.constants:
        out.append(f"{c.name}: Final = {c.value}\n")
        out.append(doc(c.doc))
    return "".join(out)


def _structs(spec: Spec) -> str:
    """The field sets that are types of their own: a mutable dataclass to count or keep the values
    in, a frozen one to hand them out, and the tuple of field names (the order of the messages)."""
    out = [banner(spec, "#"), doc("Field sets the spec declares as structs (see [[field_sets]] in the spec).")]
    out.append("\nfrom __future__ import annotations\n\nfrom dataclasses import dataclass\nfrom typing import Final\n")
    for fs in spec.structs:
        listed = "".join(f'    "{f.name}",\n' for f in fs.fields)
        out.append(f"\n{fs.name.upper()}: Final[tuple[str, ...]] = (\n{listed})\n")
        out.append(doc(f"Field names of {fs.struct}, in wire order."))
        for cls, frozen, what in (
            (fs.struct, False, "Kept (and counted) in place."),
            (f"{fs.struct}Snapshot", True, f"The values of a {fs.struct} at one moment."),
        ):
            deco = "@dataclass(frozen=True, slots=True)" if frozen else "@dataclass(slots=True)"
            out.append(f"\n\n{deco}\nclass {cls}:\n")
            out.append(doc(f"{fs.doc} {what}", "    "))
            out.append("\n")
            for f in fs.fields:
                out.append(f"    {f.name}: int = 0\n")
                out.append(doc(f.doc, "    "))
    exported = [n for fs in spec.structs for n in (fs.name.upper(), str(fs.struct), f"{fs.struct}Snapshot")]
    out.append("\n\n__all__ = [\n" + "".join(f'    "{n}",\n' for n in exported) + "]\n")
    return "".join(out)


def _bound_constants(m: Message) -> list[tuple[str, int]]:
    """(NAME_MIN / NAME_MAX, value) of every explicit bound of an integer field, spec order."""
    out = []
    for f in m.fields:
        if f.is_float or f.enum is not None or f.max_len is not None:
            continue
        for suffix, value in (("MIN", f.min), ("MAX", f.max)):
            if value is not None:
                out.append((f"{f.name.upper()}_{suffix}", int(value)))
    return out


def enum_classes(enums: tuple[Enum, ...]) -> str:
    """`import enum` and one IntEnum / IntFlag per enum, then __all__."""
    out = ["\nimport enum\n"]
    for e in enums:
        base = "IntFlag" if e.flags else "IntEnum"
        out.append(f"\n\nclass {e.name}(enum.{base}):\n")
        out.append(doc(e.doc, "    "))
        out.append("\n")
        for v in e.values:
            lit = f"0x{v.value:X}" if e.flags else str(v.value)
            out.append(f"    {v.name} = {lit}\n")
            out.append(doc(v.doc, "    "))
    out.append("\n\n__all__ = [" + ", ".join(f'"{e.name}"' for e in enums) + "]\n")
    return "".join(out)


def _enums(spec: Spec) -> str:
    return banner(spec, "#") + doc("Enumerations and bit flags.") + enum_classes(spec.enums)


def _struct_format(m: Message) -> str:
    codes = []
    for f in m.fields:
        if f.max_len is not None:
            continue
        code = PRIMITIVES[f.prim][2]
        codes.append(f"{f.count}{code}" if f.count else code)
    return "<" + "".join(codes)


def _py_type(f: Field) -> str:
    if f.max_len is not None:
        return "str" if f.prim == "char" else "bytes"
    elem = f.enum.name if f.enum else ("float" if f.is_float else "int")
    if f.count is not None:
        return "tuple[" + ", ".join([elem] * f.count) + "]"
    return elem


def _kind(f: Field) -> str:
    if f.max_len is not None:
        return "str" if f.prim == "char" else "bytes"
    if f.enum is not None:
        return "flags" if f.enum.flags else "enum"
    return "float" if f.is_float else "int"


def _field_info(f: Field) -> str:
    lo, hi = (0, f.enum.mask) if f.enum is not None and f.enum.flags else (f.lo, f.hi)
    if f.enum is not None and not f.enum.flags:
        lo, hi = min(v.value for v in f.enum.values), max(v.value for v in f.enum.values)
    if f.max_len is not None:
        lo, hi = 0, PRIMITIVES[f.prim][4] or 0
    args = [repr(f.name), repr(f.type_text), repr(_kind(f)), num(lo), num(hi)]
    if f.unit:
        args.append(f"unit={f.unit!r}")
    if f.count is not None:
        args.append(f"count={f.count}")
    if f.max_len is not None:
        args.append(f"max_len={f.max_len}")
    if f.enum is not None:
        args.append(f"enum={f.enum.name}")
    return "FieldInfo(" + ", ".join(args) + ")"


def _fast_conditions(f: Field) -> list[str]:
    """What struct.pack does not check for us: spec ranges narrower than the type, f32 finiteness
    (NaN fails every comparison), enum membership, trailing-array length. An expression that meets
    a wrong type raises TypeError, which pack() turns into the slow, precise diagnosis."""
    attr = f"self.{f.name}"
    if f.max_len is not None:
        return [f"len({attr}) <= {f.max_len}"]
    if f.enum is not None:
        return [f"{attr} in _{f.enum.name.upper()}"]
    _, _, _, tlo, thi = PRIMITIVES[f.prim]
    if not f.is_float and f.lo == tlo and f.hi == thi:
        return [f"len({attr}) == {f.count}"] if f.count else []
    elems = [f"{attr}[{k}]" for k in range(f.count)] if f.count else [attr]
    conds = [f"len({attr}) == {f.count}"] if f.count else []
    for e in elems:
        conds.append(f"{num(f.lo)} <= {e} <= {num(f.hi)}")
    return conds


def _unpack_expr(f: Field, idx: int) -> tuple[str, int]:
    """Expression building the field from the unpacked tuple `v`, and how many slots it used."""
    if f.count is not None:
        items = ", ".join(f"v[{idx + k}]" for k in range(f.count))
        return f"({items})", f.count
    return f"v[{idx}]", 1


def _message(m: Message) -> str:
    return _class_head(m) + _pack(m) + _unpack(m)


def _class_head(m: Message) -> str:
    """The class line, its docstring, its class constants and FIELDS, and its fields."""
    cls = m.class_name
    out = ["\n\n@dataclass(frozen=True, slots=True)\n", f"class {cls}(Message):\n"]
    out.append(doc(f"{m.name} (0x{m.id:02X}, {m.direction.replace('_', ' ')}, {m.delivery}): {m.doc}", "    "))
    out.append("\n")
    out.append(f"    MSG_ID: ClassVar[int] = 0x{m.id:02X}\n")
    out.append(f'    NAME: ClassVar[str] = "{m.name}"\n')
    out.append(f"    CRC_EXTRA: ClassVar[int] = 0x{m.crc_extra:02X}\n")
    out.append(f"    PAYLOAD_SIZE: ClassVar[int] = {m.payload_size}\n")
    out.append(f"    PAYLOAD_MAX: ClassVar[int] = {m.payload_max}\n")
    out.append(f"    DIRECTION: ClassVar[Direction] = Direction.{m.direction.upper()}\n")
    out.append(f"    DELIVERY: ClassVar[Delivery] = Delivery.{m.delivery.upper()}\n")
    for name, value in _bound_constants(m):
        out.append(f"    {name}: ClassVar[int] = {value}\n")
    infos = "".join(f"        {_field_info(f)},\n" for f in m.fields)
    out.append(
        f"    FIELDS: ClassVar[tuple[FieldInfo, ...]] = (\n{infos}    )\n"
        if m.fields
        else "    FIELDS: ClassVar[tuple[FieldInfo, ...]] = ()\n"
    )
    if m.fields:
        out.append("\n")
    for f in m.fields:
        out.append(f"    {f.name}: {_py_type(f)}\n")
        unit = f" [{f.unit}]" if f.unit else ""
        out.append(doc(f.doc + unit, "    "))
    return "".join(out)


def _pack(m: Message) -> str:
    """pack(): a fast path of inline checks plus struct's own; any failure is diagnosed slowly and
    precisely by first_invalid(), which walks FIELDS."""
    out = ["\n    def pack(self) -> bytes:\n"]
    fixed = [f for f in m.fields if f.max_len is None]
    args = ", ".join(f"*self.{f.name}" if f.count else f"self.{f.name}" for f in fixed)
    packed = f"_S_{m.name}.pack({args})" if fixed else 'b""'
    tail = m.trailing
    if tail is not None:
        conv = f'self.{tail.name}.encode("ascii")' if tail.prim == "char" else f"bytes(self.{tail.name})"
        packed = f"{packed} + {conv}"
    conds = [c for f in m.fields for c in _fast_conditions(f)]
    # struct packs True/False as 1/0; a bool where a number belongs is a caller's bug, refuse it.
    values = [
        f"self.{f.name}[{k}]" if f.count else f"self.{f.name}"
        for f in m.fields
        if f.max_len is None
        for k in range(f.count or 1)
    ]
    if values:
        conds.append(f"bool not in set(map(type, ({', '.join(values)},)))")
    if not m.fields:
        out.append(f"        return {packed}\n")
    else:
        out.append("        try:\n")
        if conds:
            joined = " and ".join(conds)
            out.append(f"            if {joined}:\n                return {packed}\n")
        else:
            out.append(f"            return {packed}\n")
        out.append("        except (struct.error, TypeError, ValueError, AttributeError, OverflowError):\n")
        out.append("            pass\n")
        out.append("        raise first_invalid(self)\n")
    return "".join(out)


def _unpack(m: Message) -> str:
    """unpack(): exact length rule, enum and flag values checked, nothing else trusted."""
    tail = m.trailing
    out = ["\n    @classmethod\n", f"    def unpack(cls, payload: bytes) -> {m.class_name}:\n"]
    if tail is None:
        out.append(f"        if len(payload) != {m.payload_size}:\n")
        out.append(
            f'            raise decode_error(cls, f"payload is {{len(payload)}} bytes, expected {m.payload_size}")\n'
        )
    else:
        out.append(f"        if not {m.payload_size} <= len(payload) <= {m.payload_max}:\n")
        out.append(
            f'            raise decode_error(cls, f"payload is {{len(payload)}} bytes, '
            f'expected {m.payload_size}..{m.payload_max}")\n'
        )
    if not m.fields:
        out.append("        return cls()\n")
        return "".join(out)
    fixed = [f for f in m.fields if f.max_len is None]
    if fixed:
        src = "payload" if tail is None else f"payload[:{m.payload_size}]"
        out.append(f"        v = _S_{m.name}.unpack({src})\n")
    exprs = []
    idx = 0
    for f in fixed:
        if f.enum is not None:
            # Table lookup: several times faster than calling the enum, and None for unknown values.
            what = "has bits outside" if f.enum.flags else "is not a value of"
            out.append(f"        {f.name} = _{f.enum.name.upper()}.get(v[{idx}])\n")
            out.append(f"        if {f.name} is None:\n")
            out.append(f'            raise decode_error(cls, f"{f.name} {{v[{idx}]}} {what} {f.enum.name}")\n')
            exprs.append(f.name)
            idx += 1
            continue
        expr, used = _unpack_expr(f, idx)
        exprs.append(expr)
        idx += used
    if tail is not None:
        out.append(f"        tail = payload[{m.payload_size}:]\n")
        if tail.prim == "char":
            out.append("        if not tail.isascii():\n")
            out.append(f'            raise decode_error(cls, "{tail.name} is not ASCII")\n')
            exprs.append('tail.decode("ascii")')
        else:
            exprs.append("bytes(tail)")
    # Decoding is the hot path: fill the slots directly instead of the frozen __init__, which
    # pays for object.__setattr__ on every field (about twice as slow).
    out.append("        self = _new(cls)\n")
    for f, expr in zip(m.fields, exprs, strict=True):
        out.append(f"        _{m.name}_{f.name.upper()}(self, {expr})\n")
    out.append("        return self\n")
    return "".join(out)


def _setters(m: Message) -> str:
    return "".join(f'_{m.name}_{f.name.upper()} = slot_setter({m.class_name}, "{f.name}")\n' for f in m.fields)


def _messages(spec: Spec) -> str:
    enums_used = sorted({f.enum.name for m in spec.messages for f in m.fields if f.enum is not None})
    out = [banner(spec, "#"), doc("Message classes: frozen, slotted dataclasses with pack() and unpack()."), "\n"]
    out.append("from __future__ import annotations\n\n")
    out.append("import struct\nfrom dataclasses import dataclass\nfrom typing import ClassVar\n\n")
    out.append(f"from protocol.generated.enums import {', '.join(enums_used)}\n")
    names = ["Delivery", "Direction", "FieldInfo", "Message", "decode_error", "first_invalid", "slot_setter"]
    out.append("from protocol.codec.message import (\n" + "".join(f"    {n},\n" for n in names) + ")\n\n")
    out.append("_new = object.__new__\n")
    for name in enums_used:
        e = spec.enum(name)
        if e.flags:
            table = f"{{v: {name}(v) for v in range(0x{e.mask:X} + 1) if not v & ~0x{e.mask:X}}}"
        else:
            table = f"{{int(m): m for m in {name}}}"
        out.append(f"_{name.upper()}: dict[int, {name}] = {table}\n")
    out.append("\n")
    for m in spec.messages:
        if any(f.max_len is None for f in m.fields):
            out.append(f'_S_{m.name} = struct.Struct("{_struct_format(m)}")\n')
    for m in spec.messages:
        out.append(_message(m))
        if m.fields:
            out.append("\n\n" + _setters(m))
    out.append("\n\nALL_MESSAGES: tuple[type[Message], ...] = (\n")
    out.extend(f"    {m.class_name},\n" for m in spec.messages)
    out.append(")\n")
    out.append('"""Every message class, in spec order."""\n\n')
    out.append("BY_ID: dict[int, type[Message]] = {m.MSG_ID: m for m in ALL_MESSAGES}\n")
    out.append('"""Message class by msg_id."""\n\n')
    names = ["ALL_MESSAGES", "BY_ID"] + [m.class_name for m in spec.messages]
    out.append("__all__ = [\n" + "".join(f'    "{n}",\n' for n in names) + "]\n")
    return "".join(out)


def _state_machine(spec: Spec) -> str:
    sm = spec.state_machine
    out = [banner(spec, "#"), doc(f"Session state machine table. {sm.doc}"), "\n"]
    out.append("from __future__ import annotations\n\nimport enum\nfrom dataclasses import dataclass\n")
    # Guards count from 1 so that no guard is ever falsy; C++ uses the same numbers.
    for cls, items, flag, first in (
        ("SessionState", sm.states, False, 0),
        ("SessionEvent", sm.events, False, 0),
        ("Guard", sm.guards, False, 1),
        ("Action", sm.actions, True, 0),
    ):
        base = "IntFlag" if flag else "IntEnum"
        out.append(f"\n\nclass {cls}(enum.{base}):\n")
        for i, n in enumerate(items, first):
            value = f"1 << {i}" if flag else str(i)
            out.append(f"    {n.name.upper()} = {value}\n")
            out.append(doc(n.doc, "    "))
    out.append(
        "\n\n@dataclass(frozen=True, slots=True)\nclass Transition:\n"
        '    """One row: in `source`, on `event`, if `guard` holds (is false when `negated`):\n'
        '    go to `target` and do `actions`."""\n\n'
        "    source: SessionState\n    event: SessionEvent\n    guard: Guard | None\n    negated: bool\n"
        "    target: SessionState\n    actions: Action\n"
    )
    out.append(f"\n\nINITIAL_STATE = SessionState.{sm.initial}\n\n")
    out.append("TRANSITIONS: tuple[Transition, ...] = (\n")
    for src, event, guard, negated, to, actions in sm.rows():
        acts = " | ".join(f"Action.{a.upper()}" for a in actions) or "Action(0)"
        g = f"Guard.{guard.upper()}" if guard else "None"
        out.append(
            f"    Transition(SessionState.{src}, SessionEvent.{event}, {g}, {negated}, SessionState.{to}, {acts}),\n"
        )
    out.append(")\n")
    out.append('"""Rows in spec order; the first row matching (state, event) whose guard holds fires."""\n')
    return "".join(out)


_CONSTRUCT = {
    "u8": "Int8ul",
    "i8": "Int8sl",
    "u16": "Int16ul",
    "i16": "Int16sl",
    "u32": "Int32ul",
    "i32": "Int32sl",
    "f32": "Float32l",
}


def _oracle(spec: Spec) -> str:
    out = [banner(spec, "#")]
    out.append(
        doc(
            "construct declarations of every payload: an independent oracle for the codec in tests,\n"
            "and the field-by-field view behind `roverlink decode`."
        )
    )
    out.append("\nfrom typing import Any\n\n")
    out.append("from construct import Array, Bytes, GreedyBytes, Int16ul, Struct, Int8ul  # noqa: F401\n")
    out.append("from construct import Float32l, Int8sl, Int16sl, Int32sl, Int32ul  # noqa: F401\n\n")
    out.append('BODY: Any = Struct("msg_id" / Int8ul, "seq" / Int8ul, "rest" / GreedyBytes)\n')
    out.append('"""Decoded frame body; the last two bytes of `rest` are the CRC (little-endian)."""\n\n')
    out.append("PAYLOADS: dict[int, Any] = {\n")
    for m in spec.messages:
        parts = []
        for f in m.fields:
            if f.max_len is not None:
                parts.append(f'"{f.name}" / GreedyBytes')
            elif f.count is not None:
                parts.append(f'"{f.name}" / Array({f.count}, {_CONSTRUCT[f.prim]})')
            else:
                parts.append(f'"{f.name}" / {_CONSTRUCT[f.prim]}')
        out.append(f"    0x{m.id:02X}: Struct({', '.join(parts)}),  # {m.name}\n")
    out.append("}\n\n")
    out.append("NAMES: dict[int, str] = {\n")
    out.extend(f'    0x{m.id:02X}: "{m.name}",\n' for m in spec.messages)
    out.append("}\n\n")
    out.append("CRC_EXTRA: dict[int, int] = {\n")
    out.extend(f"    0x{m.id:02X}: 0x{m.crc_extra:02X},\n" for m in spec.messages)
    out.append("}\n")
    return "".join(out)
