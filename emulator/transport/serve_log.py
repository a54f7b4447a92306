"""The serve loop's progress lines for what happened to the emulated robot, in words.

A team driving the pty sees only what the board reports: a failsafe after a collision, a boot
after an injected reset. These lines say what the emulator did, at its virtual time, so such an
event is not taken for a fault in the team's own wiring or code.
"""

from __future__ import annotations

from emulator.truth import FaultRecord
from emulator.world.world import Collision

_PER_BYTE = ("bitflip", "drop", "insert")
"""Each flipped, dropped or inserted byte has a record of its own: too many to print."""
_RATES = {
    "bitflip": "flip {} of the bits",
    "drop": "drop {} of the bytes",
    "insert": "insert a random byte after {} of the bytes",
}
_DIRECTIONS = {"h2m": "host to MCU", "m2h": "MCU to host"}
_WORDS = {
    "reset": "board reset: {} (reset pin)",
    "dtr_reset": "board reset: {}",
    "brownout": "fault: brown-out, board held in reset {}",
    "cut": "fault: link cut ({})",
    "restore": "link restored ({})",
    "noise": "fault: noise burst on {}",
    "stall": "fault: {} jammed",
    "unstall": "{} released",
    "encoder_disconnect": "fault: encoder of {} disconnected",
    "encoder_reconnect": "encoder of {} reconnected",
    "eeprom_fail": "fault: EEPROM writes fail{}",
    "eeprom_ok": "EEPROM writes work again{}",
    "traction": "fault: traction {}",
    "rx_overrun": "MCU receive buffer overrun: {}",
    "sensor_fail": "fault: emulated device failed, it sends nothing more: {}",
}


def stamp(time_us: int) -> str:
    return f"t={time_us / 1e6:.3f}s"


def fault_line(record: FaultRecord) -> str | None:
    """The line for one fault record; None for the per-byte records of a standing rate."""
    kind, detail = record.kind, record.detail
    if kind in _PER_BYTE:
        return None
    if kind == "bootloader_garbage":
        count = len(detail.split())
        text = f"bootloader: {count} garbage byte{'' if count == 1 else 's'} on the line"
    elif kind.endswith("_rate") and kind[: -len("_rate")] in _RATES:
        name = kind[: -len("_rate")]
        direction, _, rate = detail.rpartition(" ")
        where = _DIRECTIONS.get(direction, "both directions")
        if float(rate) == 0:
            text = f"{name} fault over ({where})"
        else:
            text = "fault: " + _RATES[name].format(f"{float(rate) * 100:g} %") + f" ({where})"
    elif kind in _WORDS:
        text = _WORDS[kind].format(detail)
    else:
        text = f"{kind} {detail}".strip()
    return f"{stamp(record.time_us)} {text}"


def collision_line(hit: Collision) -> str:
    """The line for a collision: what was hit, where, how fast, and what the board will see."""
    where = f"at ({hit.x_m:.2f}, {hit.y_m:.2f}) m"
    if hit.closing_m_s <= 0:
        return f"{stamp(hit.time_us)} {hit.obstacle} ran into the robot {where}"
    return (
        f"{stamp(hit.time_us)} collision with {hit.obstacle} ({hit.kind}) {where}, {hit.speed_m_s:.2f} m/s: "
        "the robot stops against it and its wheels cannot turn (the board may report ENCODER_FAULT)"
    )
