"""The two AVR parts' datasheet facts the harness needs: Arduino pin -> port and bit, the PWM
pins' timer compare outputs, and the data-space addresses of the registers behind them.

MCU facts, not robot facts: which pin a robot uses is in its robot file (the profile's `wiring`);
where that pin's level and PWM duty live is here. The pin order is the Arduino core's
(variants/standard and variants/mega, pins_arduino.h); the addresses are avr-libc's
(avr/iom328p.h, avr/iom2560.h). tests/emulator/test_simavr_wiring.py checks both against those
files when they are installed.
"""

from __future__ import annotations

from dataclasses import dataclass

from protocol.generated.enums import Board

COM_BIT = {"A": 7, "B": 5, "C": 3}
"""COMnx1 in TCCRnA: set while compare output x drives its pin (the same on every timer)."""


@dataclass(frozen=True)
class Mcu:
    name: str
    """simavr's part name."""
    pins: tuple[str, ...]
    """Port letter and bit of each Arduino pin, by pin number ("E4": PORTE bit 4)."""
    pwm: dict[int, str]
    """Arduino pin -> the timer compare output behind analogWrite() on it ("4A": OC4A)."""
    port: dict[str, int]
    """Port letter -> data-space address of PORTx."""
    tccr_a: dict[int, int]
    """Timer number -> data-space address of TCCRnA."""
    ocr: dict[str, int]
    """Compare output ("4A") of each PWM pin -> data-space address of OCRnx (the low byte of a 16-bit one)."""

    def port_bit(self, pin: int) -> tuple[str, int]:
        code = self.pins[pin]
        return code[0], int(code[1])


def _ports(letters: str) -> tuple[str, ...]:
    """ "D0-7 B0-5" -> ("D0", ..., "D7", "B0", ..., "B5")."""
    out: list[str] = []
    for run in letters.split():
        lo, hi = run[1:].split("-")
        out += [f"{run[0]}{b}" for b in range(int(lo), int(hi) + 1)]
    return tuple(out)


ATMEGA328P = Mcu(
    name="atmega328p",
    pins=_ports("D0-7 B0-5 C0-5"),
    pwm={3: "2B", 5: "0B", 6: "0A", 9: "1A", 10: "1B", 11: "2A"},
    port={"B": 0x25, "C": 0x28, "D": 0x2B},
    tccr_a={0: 0x44, 1: 0x80, 2: 0xB0},
    ocr={"0A": 0x47, "0B": 0x48, "1A": 0x88, "1B": 0x8A, "2A": 0xB3, "2B": 0xB4},
)

ATMEGA2560 = Mcu(
    name="atmega2560",
    pins=(
        *("E0", "E1", "E4", "E5", "G5", "E3", "H3", "H4", "H5", "H6", "B4", "B5", "B6", "B7"),  # 0..13
        *("J1", "J0", "H1", "H0", "D3", "D2", "D1", "D0"),  # 14..21
        *_ports("A0-7"),  # 22..29
        *("C7", "C6", "C5", "C4", "C3", "C2", "C1", "C0", "D7", "G2", "G1", "G0"),  # 30..41
        *("L7", "L6", "L5", "L4", "L3", "L2", "L1", "L0", "B3", "B2", "B1", "B0"),  # 42..53
        *_ports("F0-7 K0-7"),  # 54..69 = A0..A15
    ),
    pwm={
        **{2: "3B", 3: "3C", 4: "0B", 5: "3A", 6: "4A", 7: "4B", 8: "4C"},
        **{9: "2B", 10: "2A", 11: "1A", 12: "1B", 13: "0A", 44: "5C", 45: "5B", 46: "5A"},
    },
    port={
        **{"A": 0x22, "B": 0x25, "C": 0x28, "D": 0x2B, "E": 0x2E, "F": 0x31, "G": 0x34},
        **{"H": 0x102, "J": 0x105, "K": 0x108, "L": 0x10B},
    },
    tccr_a={0: 0x44, 1: 0x80, 2: 0xB0, 3: 0x90, 4: 0xA0, 5: 0x120},
    ocr={
        **{"0A": 0x47, "0B": 0x48, "2A": 0xB3, "2B": 0xB4},
        **{"1A": 0x88, "1B": 0x8A, "3A": 0x98, "3B": 0x9A, "3C": 0x9C},
        **{"4A": 0xA8, "4B": 0xAA, "4C": 0xAC, "5A": 0x128, "5B": 0x12A, "5C": 0x12C},
    },
)

MCUS: dict[Board, Mcu] = {Board.UNO: ATMEGA328P, Board.MEGA2560: ATMEGA2560}
"""The part on each board a reference robot can name."""
