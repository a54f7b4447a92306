"""Emit the Arduino library's generated C++11 (structs, checks, pack/unpack, dispatch, state table).

Each message struct is the packed little-endian image of its payload, so pack() and unpack() copy
bytes; each has its checks (cpp_checks.py). Only the messages a side receives are linked into its
firmware. Also emits the native tests' reflect header (cpp_reflect.py).
"""

from __future__ import annotations

from protocol.generator.emit.common import banner
from protocol.generator.emit.cpp_checks import answers_values, check_functions, enum_test, range_checks, value_checks
from protocol.generator.emit.cpp_reflect import reflect
from protocol.generator.emit.cpp_types import CTYPE, comment, ctype, int_lit
from protocol.generator.model import Enum, FieldSet, Message, Spec

LIB = "arduino/RoverLink/src/generated"
API_VERSION = 4


def emit(spec: Spec) -> dict[str, str]:
    return {
        f"{LIB}/roverlink_protocol.h": _header(spec),
        f"{LIB}/roverlink_protocol.cpp": _source(spec),
        "tests/firmware/native/generated/roverlink_reflect.h": reflect(spec),
    }


def enum_decl(e: Enum) -> str:
    """A flags enum as a struct of bits with its MASK; a plain one as an enum class with is_valid_X()."""
    out = [comment(e.doc)]
    ctype = CTYPE[e.base]
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
        out.append(f"inline bool is_valid_{e.name}({ctype} value) {{\n    {enum_test(e)}\n}}\n\n")
    return "".join(out)


def _header(spec: Spec) -> str:
    out = [banner(spec, "//")]
    out.append("// RoverLink protocol: constants, enums, message structs (packed wire images) and their checks,\n")
    out.append("// pack/unpack, dispatch, state table.\n")
    out.append("#ifndef ROVERLINK_GENERATED_PROTOCOL_H\n#define ROVERLINK_GENERATED_PROTOCOL_H\n\n")
    out.append("#include <stddef.h>\n#include <stdint.h>\n#include <string.h>\n\n")
    out.append("// The runtime's copy_payload() and f32 order keys, ROVERLINK_PACKED and ROVERLINK_PROGMEM.\n")
    out.append('#include "../wire/layout.h"\n\n')
    out.append("// The codec in src/codec/ refuses to compile against another API version (see codec.h).\n")
    out.append(f"#define ROVERLINK_GENERATED_API_VERSION {API_VERSION}\n\n")
    out.append("namespace roverlink {\nnamespace proto {\n\n")
    out.append(f"static const uint8_t PROTOCOL_VERSION = {spec.version};\n")
    out.append(f"static const uint32_t SPEC_HASH = 0x{spec.spec_hash:08X}UL;\n")
    out.append(f"static const uint8_t MAX_PAYLOAD = {spec.max_payload};\n")
    out.append(f"static const uint8_t MAX_BODY = {spec.max_body};  // msg_id + seq + payload + crc\n")
    out.append(f"static const uint8_t MAX_FRAME = {spec.max_frame};  // COBS-encoded body + delimiter\n\n")
    for c in spec.constants:
        out.append(comment(c.doc))
        out.append(f"static const {CTYPE[c.type]} {c.name} = {int_lit(c.value, c.type)};\n")
    out.append("\n")
    out.extend(enum_decl(e) for e in spec.enums)

    for fs in spec.structs:
        out.append(_field_set_struct(fs))
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


def _field_set_struct(fs: FieldSet) -> str:
    """A field set that is a type of its own: its fields in wire order, no padding (checked in the
    .cpp, with the offsets of every message that includes it)."""
    out = [f"// {fs.name}: {fs.doc}\n", f"struct {fs.struct} {{\n"]
    for f in fs.fields:
        out.append(f"    {ctype(f)} {f.name};  // {f.doc}\n")
    out.append("};\n\n")
    return "".join(out)


def _bounds(m: Message) -> str:
    """Every explicit bound of an integer field as a named constant (an enum: no storage, no ODR
    definition needed), e.g. SetAckermann::STEERING_MRAD_MAX."""
    out = []
    for f in m.fields:
        if f.is_float or f.enum is not None or f.max_len is not None:
            continue
        items = [
            f"{f.name.upper()}_{suffix} = {int_lit(int(value), f.prim)}"
            for suffix, value in (("MIN", f.min), ("MAX", f.max))
            if value is not None
        ]
        if items:
            out.append(f"    enum : {CTYPE[f.prim]} {{ {', '.join(items)} }};\n")
    return "".join(out)


def _field_indices(m: Message) -> str:
    """A request's field indices, the `detail` of NACK(OUT_OF_RANGE / INVALID_CONFIG)."""
    if m.direction != "host_to_mcu" or not range_checks(m):
        return ""
    items = "".join(f"        FIELD_{f.name.upper()} = {i},\n" for i, f in enumerate(m.fields))
    return f"    enum : uint8_t {{  // field indices (NACK detail)\n{items}    }};\n"


def _struct(m: Message) -> str:
    out = [f"// {m.name} (0x{m.id:02X}, {m.direction.replace('_', ' ')}, {m.delivery}): {m.doc}\n"]
    out.append(f"struct ROVERLINK_PACKED {m.class_name} {{\n")
    out.append(
        f"    enum : uint8_t {{ ID = 0x{m.id:02X}, CRC_EXTRA = 0x{m.crc_extra:02X}, "
        f"PAYLOAD_SIZE = {m.payload_size}, PAYLOAD_MAX = {m.payload_max} }};\n"
    )
    out.append(_bounds(m))
    out.append(_field_indices(m))
    for f in m.fields:
        unit = f" [{f.unit}]" if f.unit else ""
        if f.max_len is not None:
            out.append(f"    {CTYPE[f.prim]} {f.name}[{f.max_len}];  // {f.doc}{unit}\n")
            out.append(f"    uint8_t {f.name}_len;  // bytes used in {f.name}\n")
        elif f.count is not None:
            out.append(f"    {ctype(f)} {f.name}[{f.count}];  // {f.doc}{unit}\n")
        else:
            out.append(f"    {ctype(f)} {f.name};  // {f.doc}{unit}\n")
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
    if value_checks(m):
        out.append(f"bool values_defined(const {n}& m);\n")
    else:
        out.append(f"inline bool values_defined(const {n}&) {{ return true; }}\n")
    out.append("// False: wrong length, or a value the spec does not define (enum, flag bit, non-ASCII char).\n")
    out.append(f"inline bool unpack(const uint8_t* payload, uint8_t len, {n}& m) {{\n")
    copy = f"layout::copy_payload(payload, len, {n}::PAYLOAD_SIZE, {n}::PAYLOAD_MAX, &m)"
    out.append(f"    return {copy} && values_defined(m);\n}}\n")
    out.append("// Index of the first field outside its spec range (an undefined enum value or flag bit included),\n")
    out.append("// or ALL_FIELDS_VALID.\n")
    if range_checks(m):
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
        out.append(_included_structs(spec, m))
    for fs in spec.structs:
        out.append(f'static_assert(sizeof({fs.struct}) == {fs.size}, "{fs.struct} must have no padding");\n')
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
        out.append(check_functions(m))
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


def _included_structs(spec: Spec, m: Message) -> str:
    """A struct field set inside a message is its image: one memcpy moves the whole set."""
    out = []
    n = m.class_name
    for name in m.includes:
        fs = spec.field_set(name)
        if fs.struct is None:
            continue
        base = f"offsetof({n}, {fs.fields[0].name})"
        for f in fs.fields[1:]:
            out.append(
                f"static_assert(offsetof({n}, {f.name}) - {base} == offsetof({fs.struct}, {f.name}), "
                f'"{m.name}.{f.name} is not where {fs.struct} keeps it");\n'
            )
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
        checked = [m for m in spec.messages if m.direction == direction and value_checks(m) and not answers_values(m)]
        out.append("    bool ok = true;\n")
        for i, m in enumerate(checked):
            out.append(f"{'    } else ' if i else '    '}if (msg_id == {m.class_name}::ID) {{\n")
            out.append(f"        ok = values_defined(m.{_member(m)});\n")
        if checked:
            out.append("    }\n")
        out.append("    return ok ? DISPATCH_OK : DISPATCH_BAD_PAYLOAD;\n}\n\n")
    return "".join(out)
