"""Emit docs/protocol.md: the human-readable view of the spec."""

from __future__ import annotations

from collections.abc import Callable

from protocol.generator import hashing
from protocol.generator.emit.common import GENERATOR, num
from protocol.generator.model import Field, Message, Spec

Write = Callable[[str], None]


def emit(spec: Spec) -> dict[str, str]:
    return {"docs/protocol.md": _doc(spec)}


def _range(f: Field) -> str:
    if f.enum is not None:
        return f"[{f.enum.name}](#{f.enum.name.lower()})"
    if f.max_len is not None:
        return f"0..{f.max_len} {'ASCII chars' if f.prim == 'char' else 'bytes'}"
    if f.is_float and not f.has_explicit_range:
        return "finite"
    return f"{num(f.lo)}..{num(f.hi)}"


def _frame_bytes(m: Message, tail_len: int = 0) -> int:
    """Bytes on the wire: COBS(id, seq, payload, crc) + delimiter (one COBS code byte per <=254)."""
    body = 4 + m.payload_size + tail_len
    return body + 1 + body // 254 + 1


def _doc(spec: Spec) -> str:
    o: list[str] = []
    for section in (_intro, _frame, _crc_extra, _delivery_classes, _message_table, _messages, _enums, _state_machine):
        section(spec, o.append)
    return "".join(o).rstrip("\n") + "\n"


def _intro(spec: Spec, w: Write) -> None:
    w(f"<!-- DO NOT EDIT: generated from {spec.path} by `{GENERATOR}`. -->\n")
    w(f"<!-- spec hash: 0x{spec.spec_hash:08X} -->\n\n")
    w(f"# RoverLink protocol, version {spec.version}\n\n{spec.doc}\n\n")
    w(f"Spec hash: `0x{spec.spec_hash:08X}`. Source of truth: `{spec.path}`; this page, the firmware's C++ ")
    w("and the SDK's Python are generated from it.\n\n")


def _frame(spec: Spec, w: Write) -> None:
    w("## Frame\n\n```\n")
    w("wire:  COBS( msg_id:u8 | seq:u8 | payload:0..64 bytes | crc:u16 LE ) | 0x00\n")
    w("crc:   CRC-16/CCITT-FALSE over msg_id, seq, payload, then CRC_EXTRA (1 byte, never sent)\n```\n\n")
    w("- **COBS** removes every 0x00 from the body, so a single 0x00 ends each frame. After any lost, ")
    w("inserted or flipped byte a receiver loses at most the frame containing it and the next one.\n")
    w(f"- **CRC**: {spec.crc_name}: poly `0x{spec.crc_poly:04X}`, init `0x{spec.crc_init:04X}`, no reflection, ")
    w(f"xorout `0x{spec.crc_xorout:04X}`; the check value over ASCII `123456789` is `0x{spec.crc_check:04X}`. ")
    w("Transmitted little-endian.\n")
    w("- **seq** is a per-direction counter, +1 for every frame sent, wrapping at 256. A reliable request ")
    w("that is retried is sent again with the same seq; the receiver answers again but applies it once.\n")
    w("- **Length**: the payload is exactly the message's fixed size, or the fixed size plus 0..max of a ")
    w(f"trailing array. Anything else is a length error. Max payload {spec.max_payload} bytes, so the ")
    w(f"longest frame on the wire is {spec.max_frame} bytes.\n")
    w("- **Overhead**: 6 bytes per frame (COBS code, msg_id, seq, CRC x2, delimiter).\n")
    w("- All multi-byte fields are little-endian, fixed width. `f32` is IEEE-754 single precision.\n\n")


def _crc_extra(spec: Spec, w: Write) -> None:
    """CRC_EXTRA with a worked example, and the spec hash."""
    w("### CRC_EXTRA\n\nEach message has one CRC_EXTRA byte mixed into its CRC but never transmitted, so two ")
    w("sides built from different definitions of a message reject each other's frames as CRC errors. ")
    w("It is derived from the message's signature string:\n\n```\n")
    w('signature = NAME + for each field: " " + type + " " + field_name\n')
    w('  type   = wire primitive, ":" + enum name for enums/flags, "[N]" fixed or "[..N]" variable array\n')
    w("crc      = CRC-16/CCITT-FALSE(ascii(signature))\nCRC_EXTRA = (crc & 0xFF) ^ (crc >> 8)\n```\n\n")
    example = spec.messages[0]
    sig = hashing.signature(
        example.name,
        [
            ((f"{f.prim}:{f.enum.name}" if f.enum else f.prim) + (f"[{f.count}]" if f.count else ""), f.name)
            for f in example.fields
        ],
    )
    w(f"Example: `{sig}` gives CRC_EXTRA `0x{example.crc_extra:02X}`.\n\n")
    w("### Spec hash\n\nThe first four bytes (big-endian) of SHA-256 over a canonical JSON of everything that ")
    w("affects the wire or the session: protocol version and limits, CRC parameters, constants, enum ")
    w("values, messages (ids, names, directions, delivery classes, CRC_EXTRA, fields, types, ranges) and ")
    w("the state-machine table. Doc strings and units are left out, so editing prose does not force a ")
    w("re-flash. HELLO and IDENTITY carry it; a mismatch fails the handshake closed.\n\n")


def _delivery_classes(spec: Spec, w: Write) -> None:
    w("## Delivery classes\n\n| class | meaning |\n|---|---|\n")
    w("| session | handshake and time sync: HELLO is repeated until IDENTITY; PING is answered by PONG |\n")
    w("| setpoint | latest wins, never retried; applied at the next control tick; refused with NACK when not armed |\n")
    w(
        "| reliable | host to MCU: answered by ACK, NACK(reason) or a reply carrying the request's seq; the host "
        "retries with a timeout and the firmware applies a repeated seq once. MCU to host: those answers |\n"
    )
    w("| telemetry | MCU to host, unsolicited: FEEDBACK and LOG |\n\n")


def _message_table(spec: Spec, w: Write) -> None:
    """Every message in one table, then the line budget of the setpoint and FEEDBACK streams."""
    w("## Messages\n\n| id | message | direction | class | payload bytes | frame bytes |\n|---|---|---|---|---|---|\n")
    for m in spec.messages:
        size = f"{m.payload_size}" if m.payload_max == m.payload_size else f"{m.payload_size}..{m.payload_max}"
        frame = (
            f"{_frame_bytes(m)}"
            if m.trailing is None
            else f"{_frame_bytes(m)}..{_frame_bytes(m, m.payload_max - m.payload_size)}"
        )
        arrow = "host → MCU" if m.direction == "host_to_mcu" else "MCU → host"
        w(f"| `0x{m.id:02X}` | [{m.name}](#{m.name.lower()}) | {arrow} | {m.delivery} | {size} | {frame} |\n")
    w("\n")

    feedback = next((m for m in spec.messages if m.name == "FEEDBACK"), None)
    setpoint = next((m for m in spec.messages if m.delivery == "setpoint"), None)
    rate = next((c.value for c in spec.constants if c.name == "CONTROL_RATE_HZ"), None)
    if feedback and setpoint and rate:
        fb, sp = _frame_bytes(feedback), _frame_bytes(setpoint)
        cap = 115200 / 10
        w(f"**Line budget at 115200 baud (8N1, 11520 bytes/s each way), {rate} Hz each:** ")
        w(f"{setpoint.name} {sp} bytes x {rate} = {sp * rate} B/s ({100 * sp * rate / cap:.1f} % of host → MCU); ")
        w(f"FEEDBACK {fb} bytes x {rate} = {fb * rate} B/s ({100 * fb * rate / cap:.1f} % of MCU → host); ")
        w(f"together {100 * (sp + fb) * rate / (2 * cap):.1f} % of the full-duplex line.\n\n")


def _messages(spec: Spec, w: Write) -> None:
    for m in spec.messages:
        arrow = "host → MCU" if m.direction == "host_to_mcu" else "MCU → host"
        w(f"### {m.name}\n\n`0x{m.id:02X}` · {arrow} · {m.delivery} · CRC_EXTRA `0x{m.crc_extra:02X}` · ")
        w(f"class `{m.class_name}`\n\n{m.doc}\n\n")
        if not m.fields:
            w("No payload.\n\n")
            continue
        w("| offset | field | type | unit | valid | description |\n|---|---|---|---|---|---|\n")
        off = 0
        for f in m.fields:
            w(f"| {off} | `{f.name}` | `{f.type_text}` | {f.unit} | {_range(f)} | {f.doc} |\n")
            off += f.size
        w("\n")


def _enums(spec: Spec, w: Write) -> None:
    """The enums and flags, then the constants."""
    w("## Enums and flags\n\n")
    for e in spec.enums:
        kind = "bit flags" if e.flags else "enum"
        w(f"### {e.name}\n\n{kind} on `{e.base}`. {e.doc}\n\n| name | value | meaning |\n|---|---|---|\n")
        for v in e.values:
            lit = f"0x{v.value:02X}" if e.flags else str(v.value)
            w(f"| `{v.name}` | {lit} | {v.doc} |\n")
        w("\n")

    w("## Constants\n\n| name | type | value | meaning |\n|---|---|---|---|\n")
    for c in spec.constants:
        w(f"| `{c.name}` | `{c.type}` | {c.value} | {c.doc} |\n")
    w("\n")


def _state_machine(spec: Spec, w: Write) -> None:
    sm = spec.state_machine
    w(f"## Session state machine\n\n{sm.doc}\n\n")
    w("Rows are tried in order for the current state and event; the first whose guard holds fires. ")
    w("A (state, event) pair with no row changes nothing. The firmware and the emulator both run this ")
    w("table (generated into C++ and Python), so they cannot disagree with this page.\n\n")
    w("```mermaid\nstateDiagram-v2\n")
    w(f"    [*] --> {sm.initial}\n")
    seen: set[tuple[str, str, str]] = set()
    for src, event, guard, negated, to, _acts in sm.rows():
        if src == to and event in ("VALID_FRAME",):
            continue
        label = event + (f" [{'!' if negated else ''}{guard}]" if guard else "")
        key = (src, to, label)
        if key in seen:
            continue
        seen.add(key)
        w(f"    {src} --> {to}: {label}\n")
    w("```\n\n")
    w("| from | event | guard | to | actions |\n|---|---|---|---|---|\n")
    for t in sm.transitions:
        guard = f"{'not ' if t.negated else ''}{t.guard}" if t.guard else ""
        target = t.target or "(same)"
        w(f"| {', '.join(t.sources)} | {t.event} | {guard} | {target} | {', '.join(t.actions)} |\n")
    w("\n")
    for title, items in (("States", sm.states), ("Events", sm.events), ("Guards", sm.guards), ("Actions", sm.actions)):
        w(f"**{title}**\n\n")
        for n in items:
            w(f"- `{n.name}`: {n.doc}\n")
        w("\n")
