"""Motor PWM as the user wired it: the firmware built from a robot file sets the timer behind every
motor PWM pin to its driver's frequency (protocol/spec/hardware.toml, [[pwm_drivers]] and
[[pwm_timers]]), read back from the timers' registers in simavr; `robot check` refuses a pin whose
timer cannot give it (a TB6612 on Timer0), naming why and the pins that would work."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from protocol.generator import wiring
from protocol.generator.hardware import pwm_facts
from protocol.robotfile import check, reference_path
from roverlink import firmware
from tests.firmware.test_avr_hal import sim_pins  # noqa: F401  (the simavr harness, a fixture)
from tests.support.avr_build import build_sketch, require_toolchain, write_sketch

# TCCRnB's data-space address on the ATmega2560; its low three bits select the clock (prescaler).
TCCRB = {"Timer0": 0x45, "Timer1": 0x81, "Timer2": 0xB1, "Timer3": 0x91, "Timer4": 0xA1, "Timer5": 0x121}
PRESCALER_1 = {name: 0x01 for name in TCCRB}  # 31373 Hz in the core's 8-bit phase-correct mode
CORE = {name: 0x03 for name in TCCRB} | {"Timer2": 0x04}  # the core's prescaler 64 (Timer2 codes it 100)


def _robot(tmp_path: Path, source: str, pins: dict[str, str]) -> Path:
    """A copy of a reference robot file with some of its pin lines replaced."""
    text = reference_path(source).read_text(encoding="utf-8")
    for old, new in pins.items():
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = tmp_path / "my.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _timers(sim: Path, path: Path, tmp_path: Path) -> dict[str, int]:
    """Each Mega timer's TCCRnB clock bits after the file's firmware has booted in simavr."""
    require_toolchain()
    robot = firmware.load_robot(path)
    sketch = firmware.write_sketch(robot, tmp_path / "Sketch")
    build = build_sketch(sketch, robot.board, tmp_path / "out")
    run = subprocess.run(
        [str(sim), build.board.mcu, str(build.elf), "20000", *(f"@{hex(a)}" for a in TCCRB.values())],
        input="",
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    regs = {int(w[1], 0): int(w[2]) for w in (line.split() for line in run.stdout.splitlines()) if w[:1] == ["REG"]}
    return {name: regs[address] & 0x07 for name, address in TCCRB.items()}


TB6612_MOTORS = ("{ pwm = 6, in1 = 22", "{ pwm = 7, in1 = 24")


@pytest.mark.parametrize(
    ("left", "right", "fast"),
    [
        ("6", "7", {"Timer4"}),  # the reference wiring: one timer for both
        ("5", "6", {"Timer3", "Timer4"}),  # the wiring: the right motor was left at 490 Hz
        ("44", "11", {"Timer5", "Timer1"}),
        ("10", "12", {"Timer2", "Timer1"}),
    ],
)
def test_every_tb6612_pwm_pin_gets_its_timer_set(
    sim_pins: Path,  # noqa: F811
    tmp_path: Path,
    left: str,
    right: str,
    fast: set[str],
) -> None:
    edits = {TB6612_MOTORS[0]: f"{{ pwm = {left}, in1 = 22", TB6612_MOTORS[1]: f"{{ pwm = {right}, in1 = 24"}
    timers = _timers(sim_pins, _robot(tmp_path, "diffdrive-tb6612", edits), tmp_path)
    want = {name: (PRESCALER_1 if name in fast else CORE)[name] for name in TCCRB}
    assert timers == want


def test_the_bts7960_stays_at_the_cores_frequency(sim_pins: Path, tmp_path: Path) -> None:  # noqa: F811
    timers = _timers(sim_pins, reference_path("diffdrive-bts7960"), tmp_path)
    assert timers == CORE  # specified to 25 kHz: nothing is sped up


def test_a_tb6612_on_timer0_is_refused_naming_the_pins_that_work(tmp_path: Path) -> None:
    path = _robot(tmp_path, "diffdrive-tb6612", {TB6612_MOTORS[1]: "{ pwm = 13, in1 = 24"})
    [problem] = check(path)
    text = str(problem)
    assert problem.key == "drive.motors[1].pwm"
    assert "pin 13 is on Timer0 of the MEGA2560" in text and "millis()" in text
    assert "the TB6612 needs 20000..100000 Hz" in text
    assert "(PWM pins whose timer can: 2, 3, 5, 6, 7, 8, 9, 10, 11, 12, 44, 45, 46)" in text
    # A driver run at the core's frequency may use Timer0's pins (they give 977 Hz).
    assert wiring.pwm_problem(13, "13", "MEGA2560", "BTS7960") == ""
    assert wiring.pwm_problem(5, "5", "UNO", "TB6612").startswith("pin 5 is on Timer0 of the UNO")
    # A pin with no PWM at all: the pins that would work for this driver, Timer0's left out.
    assert wiring.pwm_problem(22, "22", "MEGA2560", "TB6612") == (
        "pin 22 has no PWM output on the MEGA2560 "
        "(PWM pins whose timer can drive the TB6612: 2, 3, 5, 6, 7, 8, 9, 10, 11, 12, 44, 45, 46)"
    )


def _core_timers(board: str) -> dict[str, list[tuple[str, int]]]:
    """The Arduino core's own digitalPinToTimer table for `board` (its variant's pins_arduino.h,
    preprocessed for the board's MCU): timer -> [(channel, pin)]."""
    require_toolchain()
    spec = firmware.BOARDS[board.lower()]
    tools = firmware.Toolchain.find()
    run = subprocess.run(
        [tools.gcc, "-E", "-P", f"-mmcu={spec.mcu}", f"-I{tools.core_dir / 'variants' / spec.variant}", "-"],
        input='#define ARDUINO_MAIN\n#include "pins_arduino.h"\n',
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    )
    table = re.search(r"digital_pin_to_timer_PGM\[\]\s*=\s*\{([^}]*)\}", run.stdout)
    assert table is not None, "no digital_pin_to_timer_PGM in the variant"
    timers: dict[str, list[tuple[str, int]]] = {}
    for pin, entry in enumerate(e.strip() for e in table[1].split(",") if e.strip()):
        if m := re.fullmatch(r"TIMER(\d)([ABC])", entry):
            timers.setdefault(f"Timer{m[1]}", []).append((m[2], pin))
    return timers


def test_the_picos_slices_are_the_datasheets() -> None:
    """hardware.toml's Pico slices: GPIO n is on slice (n >> 1) & 7, channel A when n is even."""
    from protocol.generator.hardware import pwm_facts

    slices = [t for t in pwm_facts().timers if t.board == "PICO"]
    assert [t.timer for t in slices] == [f"slice {k}" for k in range(8)]
    for t in slices:
        k = int(t.timer.split()[1])
        assert all((pin >> 1) & 7 == k for pin in t.pins) and t.pins[0] == 2 * k, t
    assert sorted(p for t in slices for p in t.pins) == [p for p in range(29) if p not in (23, 24, 25)]


@pytest.mark.parametrize("board", sorted(b for b in wiring.BOARD_PINS if b != "PICO"))
def test_the_timer_table_is_the_arduino_cores(board: str) -> None:
    """hardware.toml's pins per timer, channel A first, are the core's digitalPinToTimer: the
    timer analogWrite() uses on each pin is the one the firmware speeds up."""
    core = _core_timers(board)
    ours = {t.timer: list(t.pins) for t in pwm_facts().timers if t.board == board}
    assert ours == {timer: [pin for _, pin in sorted(pins)] for timer, pins in core.items()}
    assert wiring.BOARD_PINS[board].pwm == {pin for pins in core.values() for _, pin in pins}


UNO_SKETCH = """\
#include <RoverLink.h>
// The motor PWM pins of a TB6612 wired to an Uno's Timer1 and Timer2 pins, and one on Timer0.
static const uint8_t PINS[] = {%s};
void setup() {
    for (uint8_t i = 0; i < sizeof PINS; ++i) {
        roverlink::avr::pwm_ultrasonic(PINS[i]);
    }
}
void loop() {}
"""


@pytest.mark.parametrize(
    ("pins", "fast"),
    [((9, 3), {"Timer1", "Timer2"}), ((10, 11), {"Timer1", "Timer2"}), ((5, 6), set())],
)
def test_uno_timers_behind_each_pin(sim_pins: Path, tmp_path: Path, pins: tuple[int, ...], fast: set[str]) -> None:  # noqa: F811
    """On the Uno (no example drives a TB6612 there: it needs four external interrupts for the
    encoders) the HAL call the sketch makes per pin, with the Uno's timers read back; Timer0's pins
    (5, 6) are left alone, as `robot check` refuses them for a TB6612."""
    require_toolchain()
    uno = {"Timer0": 0x45, "Timer1": 0x81, "Timer2": 0xB1}
    sketch = write_sketch(tmp_path, "UnoPwm", UNO_SKETCH % ", ".join(map(str, pins)))
    build = build_sketch(sketch, "uno", tmp_path / "out")
    run = subprocess.run(
        [str(sim_pins), build.board.mcu, str(build.elf), "5000", *(f"@{hex(a)}" for a in uno.values())],
        input="",
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    regs = {int(w[1], 0): int(w[2]) for w in (line.split() for line in run.stdout.splitlines()) if w[:1] == ["REG"]}
    got = {name: regs[address] & 0x07 for name, address in uno.items()}
    assert got == {name: (PRESCALER_1 if name in fast else CORE)[name] for name in uno}
    for pin in pins:  # the table's timers are the core's (digitalPinToTimer)
        timer = pwm_facts().timer_of("UNO", pin)
        assert timer is not None and (timer.timer in fast) == (timer.timer != "Timer0")
