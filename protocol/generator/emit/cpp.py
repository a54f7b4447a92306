"""Emit the Arduino library's generated C++11 (structs, checks, pack/unpack, dispatch, state table).

Each message struct is the packed little-endian image of its payload, so pack() and unpack() copy
bytes. The checks are code per message: values_defined() (enums, flag bits, ASCII: what unpack()
refuses) and check_ranges() (the spec ranges: the first field outside its range). Integers compare
as integers; a float compares by its order key (src/codec/layout.h), so no floating-point code is
needed. Only the messages a side receives are linked into its firmware.

Also emits tests/native/generated/roverlink_reflect.h: a test-only text interface (print fields,
set fields by name) that lets the Python tests drive the C++ codec field by field.
"""

from __future__ import annotations

import re
import struct

from protocol.generator.emit.common import banner
from protocol.generator.model import PRIMITIVES, Enum, Field, Message, Spec

LIB = "arduino/RoverLink/src/generated"
API_VERSION = 4

_CTYPE = {
    "u8": "uint8_t",
    "i8": "int8_t",
    "u16": "uint16_t",
    "i16": "int16_t",
    "u32": "uint32_t",
    "i32": "int32_t",
    "f32": "float",
    "char": "char",
}


def emit(spec: Spec) -> dict[str, str]:
    return {
        f"{LIB}/roverlink_protocol.h": _header(spec),
        f"{LIB}/roverlink_protocol.cpp": _source(spec),
        "tests/native/generated/roverlink_reflect.h": _reflect(spec),
    }


def _comment(text: str, indent: str = "") -> str:
    return f"{indent}// {text}\n"


def _ctype(f: Field) -> str:
    if f.enum is not None and not f.enum.flags:
        return f.enum.name
    return _CTYPE[f.prim]


def _int_lit(value: int, prim: str) -> str:
    if prim == "u32":
        return f"{value}UL"
    if prim == "i32":
        # INT32_MIN cannot be written as a literal without overflow warnings.
        return "(-2147483647L - 1)" if value == -(2**31) else f"{value}L"
    return str(value)


def _float_lit(value: float) -> str:
    text = repr(float(value))
    if "e" not in text and "." not in text:
        text += ".0"
    return text + "f"


# -- header ------------------------------------------------------------------------------------
def _header(spec: Spec) -> str:
    out = [banner(spec, "//")]
    out.append("// RoverLink protocol: constants, enums, message structs (packed wire images) and their checks,\n")
    out.append("// pack/unpack, dispatch, state table.\n")
    out.append("#ifndef ROVERLINK_GENERATED_PROTOCOL_H\n#define ROVERLINK_GENERATED_PROTOCOL_H\n\n")
    out.append("#include <stddef.h>\n#include <stdint.h>\n#include <string.h>\n\n")
    out.append("// The runtime's copy_payload() and f32 order keys, ROVERLINK_PACKED and ROVERLINK_PROGMEM.\n")
    out.append('#include "../codec/layout.h"\n\n')
    out.append("// The runtime in src/codec/ refuses to compile against another API version (see codec.h).\n")
    out.append(f"#define ROVERLINK_GENERATED_API_VERSION {API_VERSION}\n\n")
    out.append("namespace roverlink {\nnamespace proto {\n\n")
    out.append(f"static const uint8_t PROTOCOL_VERSION = {spec.version};\n")
    out.append(f"static const uint32_t SPEC_HASH = 0x{spec.spec_hash:08X}UL;\n")
    out.append(f"static const uint8_t MAX_PAYLOAD = {spec.max_payload};\n")
    out.append(f"static const uint8_t MAX_BODY = {spec.max_body};  // msg_id + seq + payload + crc\n")
    out.append(f"static const uint8_t MAX_FRAME = {spec.max_frame};  // COBS-encoded body + delimiter\n\n")
    for c in spec.constants:
        out.append(_comment(c.doc))
        out.append(f"static const {_CTYPE[c.type]} {c.name} = {_int_lit(c.value, c.type)};\n")
    out.append("\n")
    for e in spec.enums:
        out.append(_comment(e.doc))
        ctype = _CTYPE[e.base]
        if e.flags:
            out.append(f"struct {e.name} {{\n    enum : {ctype} {{\n")
            for v in e.values:
                out.append(f"        {v.name} = 0x{v.value:X},  // {v.doc}\n")
            out.append(f"    }};\n    static const {ctype} MASK = 0x{e.mask:X};\n}};\n\n")
        else:
            out.append(f"enum class {e.name} : {ctype} {{\n")
            for v in e.values:
                out.append(f"    {v.name} = {v.value},  // {v.doc}\n")
            out.append("};\n")
            out.append(f"inline bool is_valid_{e.name}({ctype} value) {{\n    {_enum_test(e)}\n}}\n\n")

    out.append("// Length rule of a msg_id: payload of min_payload..max_payload bytes; and its direction.\n")
    out.append(
        "struct MessageBounds {\n    uint8_t crc_extra;\n    uint8_t min_payload;\n    uint8_t max_payload;\n"
        "    bool host_to_mcu;\n};\n"
    )
    out.append("// False for an msg_id the spec does not define (a table lookup).\n")
    out.append("bool message_bounds(uint8_t msg_id, MessageBounds& out);\n\n")
    out.append("// Returned by check_ranges() when every field is inside its spec range.\n")
    out.append("static const uint8_t ALL_FIELDS_VALID = 0xFF;\n\n")

    for m in spec.messages:
        out.append(_struct(m))
    out.append(_dispatch(spec))
    out.append(_sm_header(spec))
    out.append("}  // namespace proto\n}  // namespace roverlink\n\n#endif  // ROVERLINK_GENERATED_PROTOCOL_H\n")
    return "".join(out)


def _struct(m: Message) -> str:
    out = [f"// {m.name} (0x{m.id:02X}, {m.direction.replace('_', ' ')}, {m.delivery}): {m.doc}\n"]
    out.append(f"struct ROVERLINK_PACKED {m.class_name} {{\n")
    out.append(
        f"    enum : uint8_t {{ ID = 0x{m.id:02X}, CRC_EXTRA = 0x{m.crc_extra:02X}, "
        f"PAYLOAD_SIZE = {m.payload_size}, PAYLOAD_MAX = {m.payload_max} }};\n"
    )
    for f in m.fields:
        unit = f" [{f.unit}]" if f.unit else ""
        if f.max_len is not None:
            out.append(f"    {_CTYPE[f.prim]} {f.name}[{f.max_len}];  // {f.doc}{unit}\n")
            out.append(f"    uint8_t {f.name}_len;  // bytes used in {f.name}\n")
        elif f.count is not None:
            out.append(f"    {_ctype(f)} {f.name}[{f.count}];  // {f.doc}{unit}\n")
        else:
            out.append(f"    {_ctype(f)} {f.name};  // {f.doc}{unit}\n")
    out.append("};\n")
    n = m.class_name
    if not m.fields:
        out.append(f"inline uint8_t pack(const {n}&, uint8_t*) {{ return 0; }}\n")
        out.append(f"inline bool unpack(const uint8_t*, uint8_t len, {n}&) {{ return len == 0; }}\n")
        out.append(f"inline uint8_t check_ranges(const {n}&) {{ return ALL_FIELDS_VALID; }}\n\n")
        return "".join(out)
    out.append("// Returns the payload length.\n")
    tail = m.trailing
    if tail is None:
        out.append(
            f"inline uint8_t pack(const {n}& m, uint8_t* payload) {{\n"
            f"    memcpy(payload, &m, {n}::PAYLOAD_SIZE);\n    return {n}::PAYLOAD_SIZE;\n}}\n"
        )
    else:
        out.append(
            f"inline uint8_t pack(const {n}& m, uint8_t* payload) {{\n"
            f"    return layout::pack_tail(&m, {n}::PAYLOAD_SIZE, m.{tail.name}_len, {tail.max_len}, payload);\n}}\n"
        )
    out.append("// Whether every enum, flags and char field holds a value the spec defines.\n")
    if _value_checks(m):
        out.append(f"bool values_defined(const {n}& m);\n")
    else:
        out.append(f"inline bool values_defined(const {n}&) {{ return true; }}\n")
    out.append("// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).\n")
    out.append(f"inline bool unpack(const uint8_t* payload, uint8_t len, {n}& m) {{\n")
    copy = f"layout::copy_payload(payload, len, {n}::PAYLOAD_SIZE, {n}::PAYLOAD_MAX, &m)"
    out.append(f"    return {copy} && values_defined(m);\n}}\n")
    out.append("// Index of the first field outside its spec range (an undefined enum value or flag bit included),\n")
    out.append("// or ALL_FIELDS_VALID.\n")
    if _range_checks(m):
        out.append(f"uint8_t check_ranges(const {n}& m);\n\n")
    else:
        out.append(f"inline uint8_t check_ranges(const {n}&) {{ return ALL_FIELDS_VALID; }}  // no ranged field\n\n")
    return "".join(out)


def _member(m: Message) -> str:
    """The union member that holds message `m` (HELLO -> hello, SET_PID -> set_pid)."""
    return m.name.lower()


_DIRECTIONS = (("host_to_mcu", "HostToMcu", "firmware"), ("mcu_to_host", "McuToHost", "host-side tools"))


def _dispatch(spec: Spec) -> str:
    out = [
        "enum DispatchResult : uint8_t {\n    DISPATCH_OK = 0,\n    DISPATCH_UNKNOWN_ID,\n"
        "    DISPATCH_BAD_PAYLOAD,     // wrong length or a value the spec does not allow\n"
        "    DISPATCH_WRONG_DIRECTION  // a known message that this side never receives\n};\n\n"
    ]
    for direction, union, who in _DIRECTIONS:
        msgs = [m for m in spec.messages if m.direction == direction]
        out.append(f"// Every {direction} message, one at a time.\nunion {union} {{\n")
        for m in msgs:
            out.append(f"    {m.class_name} {_member(m)};\n")
        out.append("};\n")
        out.append(f"// Unpacks a {direction} payload into the member of `m` that msg_id names (one table lookup,\n")
        out.append("// one copy and its checks): DISPATCH_OK, _BAD_PAYLOAD, _WRONG_DIRECTION or _UNKNOWN_ID.\n")
        if direction == "host_to_mcu":
            out.append(
                "// A reliable request's values (enum, flag bit, ASCII) are left to its check_ranges(): the\n"
                "// firmware answers a value the spec does not define with NACK(OUT_OF_RANGE, the field).\n"
            )
        out.append(
            f"DispatchResult unpack_{direction}(uint8_t msg_id, const uint8_t* payload, uint8_t len, {union}& m);\n"
        )
        out.append("// The same with msg_id's bounds already looked up (FrameDecoder::bounds() after a FRAME).\n")
        out.append(
            f"DispatchResult unpack_{direction}(const MessageBounds& b, uint8_t msg_id, const uint8_t* payload, "
            f"uint8_t len,\n{' ' * (len(direction) + 22)}{union}& m);\n\n"
        )
        out.append(f"// Decodes a payload and calls h.handle(const Msg&, seq) for {direction} messages ({who}).\n")
        out.append("template <class Handler>\n")
        out.append(
            f"DispatchResult dispatch_{direction}(uint8_t msg_id, uint8_t seq, const uint8_t* payload, uint8_t len, "
            "Handler& h) {\n"
        )
        out.append(f"    {union} m;\n    const DispatchResult r = unpack_{direction}(msg_id, payload, len, m);\n")
        out.append("    if (r != DISPATCH_OK) return r;\n    switch (msg_id) {\n")
        for m in msgs:
            out.append(f"    case {m.class_name}::ID:\n        h.handle(m.{_member(m)}, seq);\n        break;\n")
        out.append("    }\n    return DISPATCH_OK;\n}\n\n")
    return "".join(out)


def _sm_header(spec: Spec) -> str:
    sm = spec.state_machine
    out = [f"// Session state machine ({sm.doc})\n"]
    for cls, items, first in (("SessionState", sm.states, 0), ("SessionEvent", sm.events, 0), ("Guard", sm.guards, 1)):
        out.append(f"enum class {cls} : uint8_t {{\n")
        for i, n in enumerate(items, first):
            out.append(f"    {n.name.upper()} = {i},  // {n.doc}\n")
        out.append("};\n")
    out.append(f"static const uint8_t SESSION_STATE_COUNT = {len(sm.states)};\n")
    out.append(f"static const SessionState INITIAL_STATE = SessionState::{sm.initial};\n")
    out.append("struct Action {\n    enum : uint16_t {\n")
    for i, a in enumerate(sm.actions):
        out.append(f"        {a.name.upper()} = 1u << {i},  // {a.doc}\n")
    out.append("    };\n};\n\n")
    out.append("// One row per transition, grouped by event (spec order within an event), 5 bytes: source\n")
    out.append("// states (bit i: SessionState i), guard (GUARD_NONE, or a Guard with GUARD_NEGATED), target\n")
    out.append("// (TARGET_STAY: the source state), actions low byte, actions high byte. EVENT_ROWS[e] is the first\n")
    out.append("// row of event e, EVENT_ROWS[e + 1] the end of its rows. Kept in flash on AVR.\n")
    out.append(f"static const uint8_t TRANSITION_COUNT = {len(sm.transitions)};\n")
    out.append(f"static const uint8_t EVENT_COUNT = {len(sm.events)};\n")
    out.append("static const uint8_t GUARD_NONE = 0xFF;\nstatic const uint8_t GUARD_NEGATED = 0x80;\n")
    out.append("static const uint8_t TARGET_STAY = 0xFF;\n")
    out.append("extern const uint8_t TRANSITIONS[TRANSITION_COUNT][5] ROVERLINK_PROGMEM;\n")
    out.append("extern const uint8_t EVENT_ROWS[EVENT_COUNT + 1] ROVERLINK_PROGMEM;\n\n")
    out.append("struct StepResult {\n    bool matched;        // false: no row, stay and do nothing\n")
    out.append("    SessionState target;\n    uint16_t actions;    // Action bits\n};\n\n")
    out.append("// First row for (state, event) whose guard holds; guards.check(Guard) evaluates guards.\n")
    out.append("template <class Guards>\nStepResult step(SessionState state, SessionEvent event, Guards& guards) {\n")
    out.append("    StepResult r = {false, state, 0};\n")
    out.append("    const uint8_t e = static_cast<uint8_t>(event);\n")
    out.append("    const uint8_t end = ROVERLINK_READ_BYTE(&EVENT_ROWS[e + 1]);\n")
    out.append("    for (uint8_t i = ROVERLINK_READ_BYTE(&EVENT_ROWS[e]); i < end; ++i) {\n")
    out.append("        const uint8_t* row = TRANSITIONS[i];\n")
    out.append("        if (!((ROVERLINK_READ_BYTE(row) >> static_cast<uint8_t>(state)) & 1u)) {\n")
    out.append("            continue;\n        }\n")
    out.append("        const uint8_t g = ROVERLINK_READ_BYTE(row + 1);\n")
    out.append("        if (g != GUARD_NONE) {\n")
    out.append("            const bool holds = guards.check(static_cast<Guard>(g & 0x7F));\n")
    out.append("            if (holds == ((g & GUARD_NEGATED) != 0)) continue;\n        }\n")
    out.append("        const uint8_t target = ROVERLINK_READ_BYTE(row + 2);\n")
    out.append("        r.matched = true;\n")
    out.append("        if (target != TARGET_STAY) r.target = static_cast<SessionState>(target);\n")
    out.append("        r.actions = static_cast<uint16_t>(ROVERLINK_READ_BYTE(row + 3) |\n")
    out.append("                                          (ROVERLINK_READ_BYTE(row + 4) << 8));\n")
    out.append("        return r;\n    }\n    return r;\n}\n\n")
    return "".join(out)


# -- source ------------------------------------------------------------------------------------
def _source(spec: Spec) -> str:
    out = [banner(spec, "//")]
    out.append('#include "roverlink_protocol.h"\n\n')
    out.append("namespace roverlink {\nnamespace proto {\n\n")
    out.append("// Every struct is its payload's image: each member at its wire offset with its wire width (no\n")
    out.append("// int, no double, no padding), then the variable-length field's <name>_len.\n")
    for m in spec.messages:
        n = m.class_name
        out.append(f'static_assert({n}::PAYLOAD_MAX <= MAX_PAYLOAD, "{m.name} payload exceeds MAX_PAYLOAD");\n')
        if not m.fields:
            continue
        offset = 0
        for f in m.fields:
            where = f'"{m.name}.{f.name} is not at its wire offset"'
            out.append(f"static_assert(offsetof({n}, {f.name}) == {offset}, {where});\n")
            offset += f.size
        tail = m.trailing
        if tail is not None:
            out.append(
                f"static_assert(offsetof({n}, {tail.name}_len) == {n}::PAYLOAD_MAX, "
                f'"{m.name}.{tail.name}_len must follow the payload image");\n'
            )
        size = f"{n}::PAYLOAD_MAX + 1" if tail is not None else f"{n}::PAYLOAD_MAX"
        out.append(f'static_assert(sizeof({n}) == {size}, "{m.name} is not its payload\'s image");\n')
    out.append("\n")
    ordered = _by_direction(spec)
    inbound = sum(1 for m in ordered if m.direction == "host_to_mcu")
    out.append("// msg_id, CRC_EXTRA, PAYLOAD_SIZE, PAYLOAD_MAX of every message: host to mcu first.\n")
    out.append(f"static const uint8_t MESSAGE_COUNT = {len(ordered)};\n")
    out.append(f"static const uint8_t HOST_TO_MCU_COUNT = {inbound};\n")
    out.append("static const uint8_t MESSAGES[MESSAGE_COUNT][4] ROVERLINK_PROGMEM = {\n")
    for m in ordered:
        n = m.class_name
        out.append(f"    {{{n}::ID, {n}::CRC_EXTRA, {n}::PAYLOAD_SIZE, {n}::PAYLOAD_MAX}},\n")
    out.append("};\n\n")
    out.append("bool message_bounds(uint8_t msg_id, MessageBounds& out) {\n")
    out.append("    for (uint8_t i = 0; i < MESSAGE_COUNT; ++i) {\n")
    out.append("        const uint8_t* row = MESSAGES[i];\n")
    out.append("        if (ROVERLINK_READ_BYTE(row) == msg_id) {\n")
    out.append("            out.crc_extra = ROVERLINK_READ_BYTE(row + 1);\n")
    out.append("            out.min_payload = ROVERLINK_READ_BYTE(row + 2);\n")
    out.append("            out.max_payload = ROVERLINK_READ_BYTE(row + 3);\n")
    out.append("            out.host_to_mcu = i < HOST_TO_MCU_COUNT;\n")
    out.append("            return true;\n        }\n    }\n    return false;\n}\n\n")
    out.append(_unpackers(spec))
    for m in spec.messages:
        out.append(_check_functions(m))
    sm = spec.state_machine
    if len(sm.states) > 8:
        raise ValueError("the C++ state table keeps the source states of a row in one byte: at most 8 states")
    states = [st.name for st in sm.states]
    events = [e.name for e in sm.events]
    guards = [g.name for g in sm.guards]
    actions = [a.name for a in sm.actions]
    rows = sorted(sm.transitions, key=lambda t: events.index(t.event))  # stable: spec order per event
    out.append("const uint8_t TRANSITIONS[TRANSITION_COUNT][5] ROVERLINK_PROGMEM = {\n")
    for t in rows:
        mask = sum(1 << states.index(src) for src in t.sources)
        g = "GUARD_NONE" if t.guard is None else f"{guards.index(t.guard) + 1}{' | GUARD_NEGATED' if t.negated else ''}"
        to = "TARGET_STAY" if t.target is None else str(states.index(t.target))
        bits = sum(1 << actions.index(a) for a in t.actions)
        guard_text = f" [{'!' if t.negated else ''}{t.guard}]" if t.guard else ""
        out.append(
            f"    {{0x{mask:02X}, {g}, {to}, 0x{bits & 0xFF:02X}, 0x{bits >> 8:02X}}},"
            f"  // {'|'.join(t.sources)} {t.event}{guard_text} -> {t.target or '(stay)'}\n"
        )
    starts = [sum(1 for t in rows if events.index(t.event) < i) for i in range(len(events) + 1)]
    out.append("};\n\n")
    out.append("const uint8_t EVENT_ROWS[EVENT_COUNT + 1] ROVERLINK_PROGMEM = {")
    out.append(", ".join(str(x) for x in starts))
    out.append("};\n\n}  // namespace proto\n}  // namespace roverlink\n")
    return "".join(out)


def _by_direction(spec: Spec) -> list[Message]:
    """The messages, host to mcu first (spec order within a direction)."""
    return [m for d, _, _ in _DIRECTIONS for m in spec.messages if m.direction == d]


def _unpackers(spec: Spec) -> str:
    """unpack_<direction>(): the length rule and direction from MESSAGES, one copy, the value checks."""
    out = []
    for direction, union, _ in _DIRECTIONS:
        out.append(
            f"DispatchResult unpack_{direction}(uint8_t msg_id, const uint8_t* payload, uint8_t len, {union}& m) {{\n"
        )
        out.append("    MessageBounds b;\n")
        out.append("    if (!message_bounds(msg_id, b)) {\n        return DISPATCH_UNKNOWN_ID;\n    }\n")
        out.append(f"    return unpack_{direction}(b, msg_id, payload, len, m);\n}}\n\n")
        out.append(
            f"DispatchResult unpack_{direction}(const MessageBounds& b, uint8_t msg_id, const uint8_t* payload, "
            f"uint8_t len,\n{' ' * (len(direction) + 22)}{union}& m) {{\n"
        )
        other = "!b.host_to_mcu" if direction == "host_to_mcu" else "b.host_to_mcu"
        out.append(f"    if ({other}) {{\n        return DISPATCH_WRONG_DIRECTION;\n    }}\n")
        out.append("    if (!layout::copy_payload(payload, len, b.min_payload, b.max_payload, &m)) {\n")
        out.append("        return DISPATCH_BAD_PAYLOAD;\n    }\n")
        checked = [m for m in spec.messages if m.direction == direction and _value_checks(m) and not _answers_values(m)]
        out.append("    bool ok = true;\n")
        for i, m in enumerate(checked):
            out.append(f"{'    } else ' if i else '    '}if (msg_id == {m.class_name}::ID) {{\n")
            out.append(f"        ok = values_defined(m.{_member(m)});\n")
        if checked:
            out.append("    }\n")
        out.append("    return ok ? DISPATCH_OK : DISPATCH_BAD_PAYLOAD;\n}\n\n")
    return "".join(out)


def _value_checks(m: Message) -> list[tuple[Field, str, str]]:
    """(field, C++ test of one element `v` that is true for an undefined value, comment) per checked field."""
    out = []
    for f in m.fields:
        test = _undefined_test(f)
        if test is not None:
            out.append((f, *test))
    return out


def _undefined_test(f: Field) -> tuple[str, str] | None:
    """(C++ test of one element `v` that is true for a value the field's type does not define: an
    enum value, a flag bit, a non-ASCII char; comment), or None for a field of no such type."""
    if f.enum is not None and f.enum.flags:
        width = PRIMITIVES[f.prim][0]
        undefined = ~f.enum.mask & ((1 << (8 * width)) - 1)
        return f"(v & 0x{undefined:X}u) != 0", f"{f.enum.name} bits 0x{f.enum.mask:X}"
    if f.enum is not None:
        return f"!is_valid_{f.enum.name}(static_cast<{_CTYPE[f.prim]}>(v))", f.enum.name
    if f.prim == "char":
        return "static_cast<uint8_t>(v) > 0x7F", "ASCII"
    return None


def _answers_values(m: Message) -> bool:
    """A reliable request: its receiver answers a value the spec does not define with NACK(OUT_OF_RANGE,
    the field), so its direction's dispatcher leaves the values to check_ranges()."""
    return m.direction == "host_to_mcu" and m.delivery == "reliable"


def _range_test(f: Field) -> tuple[str, str] | None:
    """(C++ test of one element `v` that is true when it is OUT of range, comment), or None. The
    values a type does not define are out of range too (enum, flag bit, ASCII), so check_ranges()
    alone vets a message whose values nothing has checked."""
    undefined = _undefined_test(f)
    if undefined is not None or f.max_len is not None:
        return undefined
    if f.is_float:  # always: a float field without a spec range still refuses NaN and infinity
        # Both zeros compare equal in the spec (and in Python): widen a bound at zero to take both.
        lo_bits = 0x80000000 if f.lo == 0 else _f32_bits(f.lo)
        hi_bits = 0x00000000 if f.hi == 0 else _f32_bits(f.hi)
        lo_key, hi_key = _key(lo_bits, "f32"), _key(hi_bits, "f32")
        test = f"!layout::f32_within(v, 0x{lo_key:08X}UL, 0x{hi_key:08X}UL)"
        return test, f"{_float_lit(f.lo)}..{_float_lit(f.hi)}, as order keys"
    _, _, _, tlo, thi = PRIMITIVES[f.prim]
    lo = int(f.min) if f.min is not None else int(tlo or 0)
    hi = int(f.max) if f.max is not None else int(thi or 0)
    # An unsigned bound is written unsigned, so the compare is unsigned on every target.
    suffix = "u" if f.prim in ("u8", "u16") else ""  # _int_lit() writes u32 as UL already
    tests = []
    if lo != tlo:
        tests.append(f"v < {_int_lit(lo, f.prim)}{suffix}")
    if hi != thi:
        tests.append(f"v > {_int_lit(hi, f.prim)}{suffix}")
    if not tests:
        return None
    return " || ".join(tests), f"{lo}..{hi}"


def _range_checks(m: Message) -> list[tuple[int, Field, str, str]]:
    """(field index, field, out-of-range test of `v`, comment) of every ranged field, spec order."""
    out = []
    for i, f in enumerate(m.fields):
        r = _range_test(f)
        if r is not None:
            out.append((i, f, *r))
    return out


_ELEMENT = re.compile(r"\bv\b")


def _each(f: Field, body: str, indent: str = "    ") -> str:
    """`body` (a statement about `v`) for the field's element, or for each element of an array."""
    if f.count is None and f.max_len is None:
        return indent + _ELEMENT.sub(f"m.{f.name}", body) + "\n"
    count = str(f.count) if f.count is not None else f"m.{f.name}_len"
    return (
        f"{indent}for (uint8_t i = 0; i < {count}; ++i) {{\n"
        f"{indent}    const {_ctype(f)} v = m.{f.name}[i];\n{indent}    {body}\n{indent}}}\n"
    )


def _check_functions(m: Message) -> str:
    """The message's values_defined() and check_ranges(), when it has something to check."""
    n = m.class_name
    out = []
    values = _value_checks(m)
    if values:
        out.append(f"bool values_defined(const {n}& m) {{\n")
        for f, test, note in values:
            out.append(f"    // {f.name}: {note}\n")
            out.append(_each(f, f"if ({test}) return false;"))
        out.append("    return true;\n}\n\n")
    ranges = _range_checks(m)
    if ranges:
        out.append(f"uint8_t check_ranges(const {n}& m) {{\n")
        for run in _runs(ranges):
            i, f, test, note = run[0]
            if len(run) < _RUN_MIN:
                for i, f, test, note in run:
                    out.append(f"    // {f.name}: {note}\n")
                    out.append(_each(f, f"if ({test}) return {i};"))
                continue
            # Adjacent fields with the same check: one loop over their bytes (one copy of the test).
            names = ", ".join(g[1].name for g in run)
            out.append(f"    // {names}: {note}\n")
            out.append(f"    for (uint8_t i = 0; i < {len(run)}; ++i) {{\n")
            out.append(f"        {_ctype(f)} v;\n")
            out.append(
                f"        memcpy(&v, reinterpret_cast<const uint8_t*>(&m) + offsetof({n}, {f.name}) + i * sizeof v, "
                "sizeof v);\n"
            )
            out.append(f"        if ({test}) return static_cast<uint8_t>({i} + i);\n    }}\n")
        out.append("    return ALL_FIELDS_VALID;\n}\n\n")
    return "".join(out)


_RUN_MIN = 2  # adjacent fields with one check that become a loop (fewer: one test each is smaller)


def _runs(ranges: list[tuple[int, Field, str, str]]) -> list[list[tuple[int, Field, str, str]]]:
    """The range checks in runs of adjacent scalar fields of one type with the same test."""

    def scalar(f: Field) -> bool:
        return f.count is None and f.max_len is None

    runs: list[list[tuple[int, Field, str, str]]] = []
    for c in ranges:
        prev = runs[-1][-1] if runs else None
        if (
            prev is not None
            and prev[0] + 1 == c[0]
            and scalar(prev[1])
            and scalar(c[1])
            and prev[1].prim == c[1].prim
            and prev[2] == c[2]
        ):
            runs[-1].append(c)
        else:
            runs.append([c])
    return runs


def _enum_test(e: Enum) -> str:
    """The body of is_valid_<Enum>(value): a range when the values are contiguous, else a switch."""
    values = sorted(v.value for v in e.values)
    lo, hi = values[0], values[-1]
    if values == list(range(lo, hi + 1)):
        return f"return value <= {hi};" if lo == 0 else f"return value >= {lo} && value <= {hi};"
    cases = " ".join(f"case {v}:" for v in values)
    return f"switch (value) {{ {cases} return true; default: return false; }}"


def _f32_bits(value: float) -> int:
    """IEEE-754 single-precision bits of `value`, rounded to nearest as a C float literal is."""
    try:
        return int.from_bytes(struct.pack("<f", value), "little")
    except OverflowError:
        return 0xFF800000 if value < 0 else 0x7F800000


def _key(value: int, prim: str) -> int:
    """The order key of an element (codec/layout.h): unsigned order = the numbers' order."""
    width = PRIMITIVES[prim][0]
    bits = value & ((1 << (8 * width)) - 1)
    if prim == "f32":
        return bits ^ 0xFFFFFFFF if bits & 0x80000000 else bits | 0x80000000
    if prim.startswith("i"):
        return bits ^ (1 << (8 * width - 1))
    return bits


def _reflect(spec: Spec) -> str:
    """print_fields()/set_field() per message, for the native cross-check tool.

    Text form of a field value: integers in decimal (enums and flags as their number), f32 as the
    hex of its IEEE-754 bits (exact), arrays comma-separated, byte/char arrays as hex.
    """
    out = [banner(spec, "//")]
    out.append("// Test-only: text view of every message for tests/native/rl_codec.cpp. Not part of the library.\n")
    out.append("#ifndef ROVERLINK_REFLECT_H\n#define ROVERLINK_REFLECT_H\n\n")
    out.append(
        '#include <stdio.h>\n#include <stdlib.h>\n#include <string.h>\n\n#include "generated/roverlink_protocol.h"\n\n'
    )
    out.append("namespace roverlink {\nnamespace reflect {\n\n")
    out.append(
        "inline void print_f32(FILE* f, float v) {\n    uint32_t bits;\n    memcpy(&bits, &v, 4);\n"
        '    fprintf(f, "0x%08lX", static_cast<unsigned long>(bits));\n}\n'
        "inline float parse_f32(const char* s) {\n    uint32_t bits = static_cast<uint32_t>(strtoul(s, NULL, 16));\n"
        "    float v;\n    memcpy(&v, &bits, 4);\n    return v;\n}\n"
        "inline void print_hex(FILE* f, const uint8_t* p, uint8_t n) {\n"
        '    for (uint8_t i = 0; i < n; ++i) fprintf(f, "%02x", p[i]);\n}\n'
        "inline uint8_t parse_hex(const char* s, uint8_t* out, uint8_t cap) {\n    uint8_t n = 0;\n"
        "    while (s[0] && s[1] && n < cap) {\n        char b[3] = {s[0], s[1], 0};\n"
        "        out[n++] = static_cast<uint8_t>(strtoul(b, NULL, 16));\n        s += 2;\n    }\n    return n;\n}\n\n"
    )
    for m in spec.messages:
        n = m.class_name
        arg = "m" if m.fields else "/*m*/"
        out.append(f"inline void print_fields(FILE* f, const proto::{n}& {arg}) {{\n")
        out.append(f'    fputs("{m.name}", f);\n')
        for fld in m.fields:
            out.append(f'    fputs(" {fld.name}=", f);\n')
            if fld.max_len is not None:
                out.append(f"    print_hex(f, reinterpret_cast<const uint8_t*>(m.{fld.name}), m.{fld.name}_len);\n")
                continue
            idx = "[k]" if fld.count else ""
            value = f"m.{fld.name}{idx}"
            if fld.is_float:
                line = f"print_f32(f, {value});"
            elif fld.prim in ("u32",):
                line = f'fprintf(f, "%lu", static_cast<unsigned long>({value}));'
            elif fld.prim in ("i32",):
                line = f'fprintf(f, "%ld", static_cast<long>({value}));'
            else:
                line = f'fprintf(f, "%ld", static_cast<long>({value}));'
            if fld.count:
                out.append(f"    for (uint8_t k = 0; k < {fld.count}; ++k) {{\n")
                out.append(f"        if (k) fputc(',', f);\n        {line}\n    }}\n")
            else:
                out.append(f"    {line}\n")
        out.append("}\n\n")
        out.append(f"inline bool set_field(proto::{n}& {arg}, const char* name, const char* value) {{\n")
        if not m.fields:
            out.append("    (void)name;\n    (void)value;\n    return false;\n}\n\n")
            continue
        for fld in m.fields:
            out.append(f'    if (strcmp(name, "{fld.name}") == 0) {{\n')
            if fld.max_len is not None:
                out.append(
                    f"        m.{fld.name}_len = parse_hex(value, reinterpret_cast<uint8_t*>(m.{fld.name}), "
                    f"{fld.max_len});\n"
                )
            else:
                ctype = _ctype(fld)
                if fld.enum is not None and not fld.enum.flags:
                    ctype = f"proto::{ctype}"
                if fld.is_float:
                    conv = "parse_f32(v)"
                elif fld.prim == "u32":
                    conv = f"static_cast<{ctype}>(strtoul(v, NULL, 10))"
                else:
                    conv = f"static_cast<{ctype}>(strtol(v, NULL, 10))"
                if fld.count:
                    out.append(
                        f"        const char* v = value;\n        for (uint8_t k = 0; k < {fld.count}; ++k) {{\n"
                    )
                    out.append(f"            m.{fld.name}[k] = {conv};\n")
                    out.append(
                        "            v = strchr(v, ',');\n            if (!v) return k == " + str(fld.count - 1) + ";\n"
                    )
                    out.append("            ++v;\n        }\n")
                else:
                    out.append(f"        const char* v = value;\n        m.{fld.name} = {conv};\n")
            out.append("        return true;\n    }\n")
        out.append("    return false;\n}\n\n")
    out.append("// Calls fn(msg) with a zeroed message of type `msg_id`; false for an unknown id.\n")
    out.append("template <class Fn>\nbool with_message(uint8_t msg_id, Fn& fn) {\n    switch (msg_id) {\n")
    for m in spec.messages:
        out.append(f"    case proto::{m.class_name}::ID: {{\n        proto::{m.class_name} m;\n")
        out.append("        memset(&m, 0, sizeof m);\n        fn(m);\n        return true;\n    }\n")
    out.append("    default:\n        return false;\n    }\n}\n\n")
    out.append("// msg_id of a message NAME, or -1.\ninline int id_of(const char* name) {\n")
    for m in spec.messages:
        out.append(f'    if (strcmp(name, "{m.name}") == 0) return proto::{m.class_name}::ID;\n')
    out.append(
        "    return -1;\n}\n\n}  // namespace reflect\n}  // namespace roverlink\n\n#endif  // ROVERLINK_REFLECT_H\n"
    )
    return "".join(out)
