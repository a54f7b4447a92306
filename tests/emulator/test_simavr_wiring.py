"""The simavr harness's wiring: the robot files' pins, through the per-MCU table, to registers.

The table (emulator/backends/simavr/mcu.py) is checked against the files it transcribes: the
Arduino core's pin maps (variants/*/pins_arduino.h) and avr-libc's register addresses
(avr/iom*.h). The wiring of each reference robot is checked against the registers the harness
watched before the pins moved to the robot files.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from emulator.backends.simavr.mcu import ATMEGA328P, ATMEGA2560, COM_BIT, Mcu
from emulator.backends.simavr.wiring import (
    Bts7960Channel,
    HBridgeChannel,
    PortPin,
    PulsePin,
    PwmPin,
    board_wiring,
    decode_pins,
)
from protocol.generated.hardware import MotorMode
from protocol.generated.profiles import PROFILES

VARIANTS = Path("/usr/share/arduino/hardware/arduino/avr/variants")
AVR_INCLUDE = Path("/usr/lib/avr/include/avr")
PARTS = [(ATMEGA328P, "standard", "iom328p.h"), (ATMEGA2560, "mega", "iom2560.h")]


def _array(text: str, name: str) -> list[str]:
    """The entries of a PROGMEM array in pins_arduino.h (comments dropped, the ATmega8 #if branch too)."""
    body = text[text.index(name) :]
    body = body[body.index("{") + 1 : body.index("};")]
    body = re.sub(r"//[^\n]*|/\*.*?\*/", "", body, flags=re.S)
    body = re.sub(r"#if[^\n]*\n.*?#else[^\n]*\n", "", body, flags=re.S)
    body = re.sub(r"#endif[^\n]*", "", body)
    return [item.strip() for item in body.split(",") if item.strip()]


@pytest.mark.parametrize(("mcu", "variant", "_header"), PARTS, ids=lambda p: getattr(p, "name", p))
def test_pin_table_is_the_arduino_cores(mcu: Mcu, variant: str, _header: str) -> None:
    path = VARIANTS / variant / "pins_arduino.h"
    if not path.is_file():
        pytest.skip(f"{path} is not installed (Debian: arduino-core-avr)")
    text = path.read_text(encoding="utf-8")
    ports = [p.removeprefix("P") for p in _array(text, "digital_pin_to_port_PGM")]
    bits = [int(re.sub(r"\D", "", b)) for b in _array(text, "digital_pin_to_bit_mask_PGM")]
    assert mcu.pins == tuple(f"{p}{b}" for p, b in zip(ports, bits, strict=True))
    timers = _array(text, "digital_pin_to_timer_PGM")
    on_timer = {pin: t.removeprefix("TIMER") for pin, t in enumerate(timers) if t != "NOT_ON_TIMER"}
    assert mcu.pwm == on_timer


@pytest.mark.parametrize(("mcu", "_variant", "header"), PARTS, ids=lambda p: getattr(p, "name", p))
def test_register_addresses_are_avr_libcs(mcu: Mcu, _variant: str, header: str) -> None:
    path = AVR_INCLUDE / header
    if not path.is_file():
        pytest.skip(f"{path} is not installed (Debian: avr-libc)")
    defs = {}
    for name, kind, value in re.findall(
        r"#define\s+(\w+)\s+_SFR_(IO|MEM)(?:8|16)\((0[xX][0-9A-Fa-f]+)\)", path.read_text()
    ):
        defs[name] = int(value, 16) + (0x20 if kind == "IO" else 0)  # I/O space -> data space
    assert {letter: defs[f"PORT{letter}"] for letter in mcu.port} == mcu.port
    assert {n: defs[f"TCCR{n}A"] for n in mcu.tccr_a} == mcu.tccr_a
    assert {out: defs[f"OCR{out}"] for out in mcu.ocr} == mcu.ocr
    assert set(mcu.ocr) == set(mcu.pwm.values())  # every PWM output has its compare register


# The registers the harness watched when they were written by hand (ATmega2560 / ATmega328P).
_PORTA, _PORTC, _PORTE, _PORTH = 0x22, 0x28, 0x2E, 0x102
_TCCR3A, _OCR3B, _OCR3C = 0x90, 0x9A, 0x9C
_TCCR4A, _OCR4A, _OCR4B = 0xA0, 0xA8, 0xAA
_TCCR1A, _OCR1A, _OCR1B = 0x80, 0x88, 0x8A
A, B, C = COM_BIT["A"], COM_BIT["B"], COM_BIT["C"]


def test_reference_robots_map_to_the_registers_they_always_used() -> None:
    tb = board_wiring(PROFILES["diffdrive-tb6612"])
    assert (tb.mcu, tb.encoders, tb.pcint_k) == ("atmega2560", (("E4", "E5"), ("D3", "D2")), False)
    assert tb.motors == (
        HBridgeChannel(
            PwmPin(_TCCR4A, A, _OCR4A, _PORTH, 3), PortPin(_PORTA, 0), PortPin(_PORTA, 1), PortPin(_PORTA, 4)
        ),
        HBridgeChannel(
            PwmPin(_TCCR4A, B, _OCR4B, _PORTH, 4), PortPin(_PORTA, 2), PortPin(_PORTA, 3), PortPin(_PORTA, 4)
        ),
    )
    assert tb.leds == (PortPin(_PORTC, 7), PortPin(_PORTC, 6), PortPin(_PORTC, 5), PortPin(_PORTC, 4))
    bts = board_wiring(PROFILES["diffdrive-bts7960"])
    assert (bts.encoders, bts.pcint_k, bts.leds) == ((("K0", "K1"), ("K2", "K3")), True, ())
    assert bts.motors == (
        Bts7960Channel(
            PwmPin(_TCCR3A, B, _OCR3B, _PORTE, 4),
            PwmPin(_TCCR3A, C, _OCR3C, _PORTE, 5),
            PortPin(_PORTA, 0),
            PortPin(_PORTA, 1),
        ),
        Bts7960Channel(
            PwmPin(_TCCR4A, A, _OCR4A, _PORTH, 3),
            PwmPin(_TCCR4A, B, _OCR4B, _PORTH, 4),
            PortPin(_PORTA, 2),
            PortPin(_PORTA, 3),
        ),
    )
    picar = board_wiring(PROFILES["picar"])
    assert (picar.mcu, picar.encoders, picar.motors) == ("atmega328p", (("D2", "D3"),), ())
    assert (picar.esc, picar.servo) == (PulsePin(_TCCR1A, A, _OCR1A), PulsePin(_TCCR1A, B, _OCR1B))


def test_decode_pins_reads_each_driver_state_from_the_registers() -> None:
    tb = board_wiring(PROFILES["diffdrive-tb6612"])
    regs = dict.fromkeys(tb.watch(), 0)
    regs[_TCCR4A] = 1 << A  # left PWM connected, right one a plain output
    regs[_OCR4A] = 51
    regs[_PORTA] = 0b10001 | 0b1100  # STBY high; left IN1 (forward); right IN1 and IN2 (brake)
    regs[_PORTC] = 1 << 7 | 1 << 4  # front left and rear right LEDs
    pins = decode_pins(tb, regs)
    assert pins.duty == (pytest.approx(0.2), 0.0) and pins.mode == (MotorMode.DRIVE, MotorMode.BRAKE)
    assert pins.leds == 0b1001
    regs[_PORTA] = 0b1111  # STBY low: both coast whatever IN1/IN2 say
    assert decode_pins(tb, regs).mode == (MotorMode.COAST, MotorMode.COAST)
    picar = board_wiring(PROFILES["picar"])
    regs = dict.fromkeys(picar.watch(), 0)
    regs[_TCCR1A] = 1 << A | 1 << B
    regs[_OCR1A], regs[_OCR1A + 1] = (2 * 1500 - 1) & 0xFF, (2 * 1500 - 1) >> 8
    regs[_OCR1B], regs[_OCR1B + 1] = (2 * 1200 - 1) & 0xFF, (2 * 1200 - 1) >> 8
    assert (decode_pins(picar, regs).esc_us, decode_pins(picar, regs).servo_us) == (1500, 1200)
