"""The AVR hardware layer on a simulated MCU: test sketches run in simavr
(tests/firmware/native/avr_hal/sim_pins.c) for Timer1 servo pulses, TB6612 / BTS7960 pins, LEDs and
encoders on external and pin-change interrupts, and every example booting and streaming frames
with its outputs in the safe state."""

from __future__ import annotations

import dataclasses
import shutil
import subprocess
from pathlib import Path

import pytest

from host_sdk import messages
from host_sdk.framing import Frame, FrameDecoder
from protocol.generated.profiles import PROFILES
from roverlink import firmware
from tests.support import make
from tests.support.avr_build import EXAMPLES, ROOT, build_sketch, write_sketch

# -- the hardware layer on a simulated MCU ----------------------------------------------------------------
# Test sketches run in simavr (tests/firmware/native/avr_hal/sim_pins.c): the harness drives encoder pins
# on a schedule and logs output pins and UART0. Digital pin levels and the register file are
# exact in simavr; the waveform of a 16-bit timer's compare output is not, so PWM and servo pulses
# are checked through the registers that make them (the sketches report them over the UART).

AVR_HAL_DIR = ROOT / "tests" / "firmware" / "native" / "avr_hal"
SIM_BUILD = ROOT / "build" / "native" / "avr_hal"
CYCLES_PER_US = 16
GRAY = ("00", "10", "11", "01")  # channel levels (A, B) at the four positions of a cycle


@dataclasses.dataclass
class SimRun:
    pins: dict[str, list[tuple[int, int]]]  # port pin -> (cycle, level) changes
    uart: bytes

    def level(self, pin: str, at_us: int) -> int:
        """Level of a watched output pin at a time (0 before its first change)."""
        level = 0
        for cycle, value in self.pins.get(pin, []):
            if cycle > at_us * CYCLES_PER_US:
                break
            level = value
        return level

    def records(self, size: int) -> list[bytes]:
        """The sketch's reports: 0xA5 then `size` bytes, back to back."""
        out, data = [], self.uart
        while len(data) >= size + 1:
            assert data[0] == 0xA5, data.hex()
            out.append(data[1 : size + 1])
            data = data[size + 1 :]
        return out


@pytest.fixture(scope="session")
def sim_pins() -> Path:
    if shutil.which("cc") is None or not Path("/usr/include/simavr/sim_avr.h").is_file():
        pytest.fail("simavr's library is required: install the Debian packages simavr libsimavr-dev libelf-dev")
    make.require_make(AVR_HAL_DIR, "sim", build=SIM_BUILD)
    return SIM_BUILD / "sim" / "sim_pins"


def simulate(
    sim: Path, result: firmware.BuildResult, duration_us: int, watch: list[str], schedule: list[str]
) -> SimRun:
    run = subprocess.run(
        [str(sim), result.board.mcu, str(result.elf), str(duration_us), *watch],
        input="\n".join(schedule) + "\n",
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    pins: dict[str, list[tuple[int, int]]] = {}
    uart = b""
    for line in run.stdout.splitlines():
        words = line.split()
        if words[:1] == ["PIN"]:
            pins.setdefault(words[2], []).append((int(words[1]), int(words[3])))
        elif words[:1] == ["UART"]:
            uart = bytes.fromhex(words[1]) if len(words) > 1 else b""
    return SimRun(pins, uart)


def quadrature(pin_a: str, pin_b: str, start_us: int, moves: list[int], step_us: int = 50) -> list[str]:
    """Schedule lines turning an encoder that rests at 11 (the pull-ups) by `moves` (+1/-1/+2)."""
    lines, position, t = [], GRAY.index("11"), start_us
    for move in moves:
        position = (position + move) % 4
        t += step_us
        a, b = GRAY[position]
        lines += [f"{t} {pin_a} {a}", f"{t} {pin_b} {b}"]
    return lines


def _by_time(*schedules: list[str]) -> list[str]:
    return sorted((line for s in schedules for line in s), key=lambda line: int(line.split()[0]))


REPORT_EVERY_10_MS = """
void report(const uint8_t* data, uint8_t size) {
    Serial.write(0xA5);
    Serial.write(data, size);
}
"""

UNO_HAL_SKETCH = (
    """\
#include <RoverLink.h>
namespace rl = roverlink::avr;

rl::QuadratureEncoder encoder(2, 3);
rl::AckermannBoard<rl::Timer1> board(encoder, rl::PulseChannel::A, rl::PulseChannel::B, A0);
void edge() { encoder.on_edge(); }
"""
    + REPORT_EVERY_10_MS
    + """
void setup() {
    Serial.begin(115200);
    board.begin();
    encoder.attach_external(edge);
    board.esc_pulse(1500);
    board.steering_pulse(1222);
}

void loop() {
    static uint32_t last;
    static bool changed;
    const uint32_t now = micros();
    if (!changed && now >= 40000UL) {
        changed = true;
        board.esc_pulse(3000);    // clamped to 2600 us
        board.steering_pulse(0);  // pulses off, line held low
    }
    if (now - last >= 10000UL) {
        last = now;
        int32_t counts[2];
        board.read_encoders(counts);
        const uint16_t errors = encoder.errors(), ocr_a = OCR1A, ocr_b = OCR1B, top = ICR1;
        uint8_t r[18];
        memcpy(r, counts, 8);
        memcpy(r + 8, &errors, 2);
        r[10] = TCCR1A;
        r[11] = TCCR1B;
        memcpy(r + 12, &ocr_a, 2);
        memcpy(r + 14, &top, 2);
        memcpy(r + 16, &ocr_b, 2);
        report(r, 18);
    }
}
"""
)


def test_uno_servo_pulses_and_encoder_on_a_simulated_atmega328p(sim_pins: Path, tmp_path: Path) -> None:
    build = build_sketch(write_sketch(tmp_path, "UnoHal", UNO_HAL_SKETCH), "uno", tmp_path / "out")
    moves = [1] * 400 + [-1] * 100 + [2]  # 100 cycles forward, 25 back, then a missed edge
    run = simulate(sim_pins, build, 80_000, ["B1", "B2"], quadrature("D2", "D3", 5_000, moves))
    reports = run.records(18)
    assert len(reports) >= 6, run.uart.hex()
    first, last = reports[1], reports[-1]  # reports[0] may precede the pulses' setup
    # Timer1: fast PWM mode 14 (WGM13:10 = 1110), clk/8, TOP 39999: 20 ms period, 0.5 us ticks.
    assert first[11] == 0b00011010
    assert int.from_bytes(first[14:16], "little") == 39999
    assert first[10] == 0b10100010  # COM1A1 | COM1B1 (non-inverting) | WGM11
    assert int.from_bytes(first[12:14], "little") == 2 * 1500 - 1  # ESC: 1500 us
    assert int.from_bytes(first[16:18], "little") == 2 * 1222 - 1  # steering: 1222 us
    assert last[10] == 0b10000010  # steering channel disconnected...
    assert run.level("B2", 79_000) == 0  # ...and its line held low
    assert int.from_bytes(last[12:14], "little") == 2 * 2600 - 1  # 3000 us clamped
    # Encoder: x4 counts on INT0/INT1; the two-step jump counts nothing and is an error.
    assert int.from_bytes(last[0:4], "little", signed=True) == 4 * 75
    assert int.from_bytes(last[4:8], "little", signed=True) == 0  # no second wheel
    assert int.from_bytes(last[8:10], "little") == 1


MEGA_TB6612_SKETCH = (
    """\
#include <RoverLink.h>
namespace rl = roverlink::avr;
using roverlink::MotorMode;

rl::Tb6612Motor left_motor(6, 22, 23, 26), right_motor(7, 24, 25, 26);
rl::QuadratureEncoder left_encoder(2, 3), right_encoder(18, 19);
rl::TurnSignalLeds leds(30, 31, 32, 33);
rl::DiffDriveBoard<rl::Tb6612Motor, rl::TurnSignalLeds> board(left_motor, right_motor, left_encoder,
                                                              right_encoder, leds, A0);
void left_edge() { left_encoder.on_edge(); }
void right_edge() { right_encoder.on_edge(); }
"""
    + REPORT_EVERY_10_MS
    + """
void setup() {
    Serial.begin(115200);
    board.begin();
    rl::pwm_ultrasonic(6);
    left_encoder.attach_external(left_edge);
    right_encoder.attach_external(right_edge);
}

void loop() {
    static uint32_t last;
    const uint32_t now = micros();
    if (now < 30000UL) {
        board.drive(0, 500, MotorMode::DRIVE);
        board.drive(1, -1000, MotorMode::DRIVE);
        board.lights(roverlink::Lights::FRONT_LEFT | roverlink::Lights::REAR_LEFT);
    } else if (now < 60000UL) {
        board.drive(0, 0, MotorMode::BRAKE);
        board.drive(1, 0, MotorMode::BRAKE);
        board.lights(roverlink::Lights::FRONT_RIGHT | roverlink::Lights::REAR_RIGHT);
    } else {
        board.drive(0, 0, MotorMode::COAST);
        board.drive(1, 0, MotorMode::COAST);
        board.lights(0);
    }
    if (now - last >= 10000UL) {
        last = now;
        int32_t counts[2];
        board.read_encoders(counts);
        uint8_t r[11];
        memcpy(r, counts, 8);
        r[8] = TCCR4A;
        r[9] = TCCR4B;
        r[10] = OCR4AL;
        report(r, 11);
    }
}
"""
)

# Mega pins as port bits: 22..26 = PA0..PA4, 6/7 = PH3/PH4, 30..33 = PC7..PC4, 2/3 = PE4/PE5,
# 18/19 = PD3/PD2, 50..53 = PB3..PB0.
TB6612_PINS = {"AIN1": "A0", "AIN2": "A1", "BIN1": "A2", "BIN2": "A3", "STBY": "A4", "PWMA": "H3", "PWMB": "H4"}
LED_PINS = {"FL": "C7", "FR": "C6", "RL": "C5", "RR": "C4"}


def test_mega_tb6612_leds_and_external_interrupt_encoders(sim_pins: Path, tmp_path: Path) -> None:
    build = build_sketch(write_sketch(tmp_path, "Tb6612Hal", MEGA_TB6612_SKETCH), "mega2560", tmp_path / "out")
    schedule = _by_time(quadrature("E4", "E5", 5_000, [1] * 200), quadrature("D3", "D2", 5_025, [-1] * 120, step_us=70))
    watch = [*TB6612_PINS.values(), *LED_PINS.values()]
    run = simulate(sim_pins, build, 90_000, watch, schedule)

    def levels(at_us: int, names: dict[str, str]) -> dict[str, int]:
        return {name: run.level(pin, at_us) for name, pin in names.items()}

    pins = {k: v for k, v in TB6612_PINS.items() if k != "PWMA"}  # PWMA is on the timer: see registers
    assert levels(25_000, pins) == {"AIN1": 1, "AIN2": 0, "BIN1": 0, "BIN2": 1, "STBY": 1, "PWMB": 1}
    assert levels(25_000, LED_PINS) == {"FL": 1, "FR": 0, "RL": 1, "RR": 0}
    assert levels(55_000, TB6612_PINS) == {k: 1 for k in TB6612_PINS}  # short brake: all high
    assert levels(55_000, LED_PINS) == {"FL": 0, "FR": 1, "RL": 0, "RR": 1}
    coast = dict.fromkeys(TB6612_PINS, 0) | {"STBY": 1}
    assert levels(85_000, TB6612_PINS) == coast
    assert levels(85_000, LED_PINS) == dict.fromkeys(LED_PINS, 0)

    reports = run.records(11)
    assert len(reports) >= 8, run.uart.hex()
    driving = reports[1]  # at ~10 ms
    assert driving[8] & 0b10000000  # COM4A1: pin 6 on the timer
    assert driving[10] == 128  # 500 permille of 255, rounded
    assert driving[9] & 0b111 == 0b001  # pwm_ultrasonic(): Timer4 at clk/1
    assert reports[-1][8] & 0b10000000 == 0  # coasting: pin 6 off the timer, low
    counts = (
        int.from_bytes(reports[-1][0:4], "little", signed=True),
        int.from_bytes(reports[-1][4:8], "little", signed=True),
    )
    assert counts == (200, -120)


MEGA_BTS7960_SKETCH = (
    """\
#include <RoverLink.h>
namespace rl = roverlink::avr;
using roverlink::MotorMode;

rl::Bts7960Motor left_motor(2, 3, 22, 23), right_motor(6, 7, 24, 25);
rl::QuadratureEncoder left_encoder(50, 51), right_encoder(52, 53);
rl::NoLights no_lights;
rl::DiffDriveBoard<rl::Bts7960Motor> board(left_motor, right_motor, left_encoder, right_encoder, no_lights, A0);
ISR(PCINT0_vect) {
    left_encoder.on_edge();
    right_encoder.on_edge();
}
"""
    + REPORT_EVERY_10_MS
    + """
void setup() {
    Serial.begin(115200);
    board.begin();
    left_encoder.enable_pin_change();
    right_encoder.enable_pin_change();
}

void loop() {
    static uint32_t last;
    const uint32_t now = micros();
    const MotorMode mode = now < 30000UL ? MotorMode::DRIVE : now < 60000UL ? MotorMode::BRAKE : MotorMode::COAST;
    board.drive(0, 1000, mode);
    board.drive(1, -400, mode);
    if (now - last >= 10000UL) {
        last = now;
        int32_t counts[2];
        board.read_encoders(counts);
        uint8_t r[10];
        memcpy(r, counts, 8);
        r[8] = TCCR4A;
        r[9] = OCR4BL;
        report(r, 10);
    }
}
"""
)
BTS_PINS = {"L_RPWM": "E4", "L_LPWM": "E5", "L_REN": "A0", "L_LEN": "A1", "R_RPWM": "H3", "R_REN": "A2", "R_LEN": "A3"}


def test_mega_bts7960_and_pin_change_encoders(sim_pins: Path, tmp_path: Path) -> None:
    build = build_sketch(write_sketch(tmp_path, "Bts7960Hal", MEGA_BTS7960_SKETCH), "mega2560", tmp_path / "out")
    # Both encoders on one pin-change vector, some edges at the same instant. Port B (pins 50..53,
    # PCINT0_vect) rather than the example's port K (A8..A11, PCINT2_vect): simavr 1.6 does not
    # model pin-change interrupts on port K. The code path is the same, only the mask register
    # and the vector differ.
    schedule = _by_time(quadrature("B3", "B2", 5_000, [1] * 150), quadrature("B1", "B0", 5_000, [-1] * 80, step_us=100))
    run = simulate(sim_pins, build, 90_000, [*BTS_PINS.values(), "H4"], schedule)

    def levels(at_us: int) -> dict[str, int]:
        return {name: run.level(pin, at_us) for name, pin in BTS_PINS.items()}

    # Driving: left forward at full duty (RPWM high), right reverse on LPWM (pin 7, on the timer).
    assert levels(25_000) == {"L_RPWM": 1, "L_LPWM": 0, "L_REN": 1, "L_LEN": 1, "R_RPWM": 0, "R_REN": 1, "R_LEN": 1}
    assert levels(55_000) == {"L_RPWM": 0, "L_LPWM": 0, "L_REN": 1, "L_LEN": 1, "R_RPWM": 0, "R_REN": 1, "R_LEN": 1}
    assert levels(85_000) == dict.fromkeys(BTS_PINS, 0)
    assert run.level("H4", 85_000) == 0

    reports = run.records(10)
    assert len(reports) >= 8, run.uart.hex()
    assert reports[1][8] & 0b00100000  # COM4B1: pin 7 on the timer while driving
    assert reports[1][9] == 102  # 400 permille of 255, rounded
    assert reports[-1][8] & 0b00100000 == 0
    counts = (
        int.from_bytes(reports[-1][0:4], "little", signed=True),
        int.from_bytes(reports[-1][4:8], "little", signed=True),
    )
    assert counts == (150, -80)


# The examples themselves, booted: the core over each board, nothing connected to the host side.
BOOT_WATCH = {
    # example: (pins that must hold the safe state when disarmed, their levels, registers to dump)
    "AckermannPiCar": ({"B1": None, "B2": None}, ["@0x80", "@0x88", "@0x89", "@0x8A", "@0x8B"]),
    # BRAKE: IN1 = IN2 = high on both channels, STBY high.
    "DiffDriveTB6612": ({"A0": 1, "A1": 1, "A2": 1, "A3": 1, "A4": 1}, []),
    # RAMP_DOWN, then COAST: both PWM low, enables low.
    "DiffDriveBTS7960": ({"E4": 0, "E5": 0, "H3": 0, "H4": 0, "A0": 0, "A1": 0, "A2": 0, "A3": 0}, []),
}


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_boots_on_a_simulated_mcu(
    sim_pins: Path, example_builds: dict[str, firmware.BuildResult], name: str
) -> None:
    result = example_builds[name]
    profile = next(p for p in PROFILES.values() if p.example == name)
    pins, registers = BOOT_WATCH[name]
    run = subprocess.run(
        [str(sim_pins), result.board.mcu, str(result.elf), "300000", *pins, *registers],
        input="",
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    lines = run.stdout.splitlines()
    uart = next(line.split()[1] for line in lines if line.startswith("UART "))
    decoder = FrameDecoder()
    frames = [e for e in decoder.feed(bytes.fromhex(uart)) if isinstance(e, Frame)]
    assert decoder.stats.frames_ok == len(frames) > 0 and decoder.stats.crc_errors == 0, decoder.stats

    identity = frames[0].message
    assert isinstance(identity, messages.Identity), frames[0]
    assert identity.board == profile.board
    assert identity.capabilities == profile.capabilities
    feedback = [f.message for f in frames if isinstance(f.message, messages.Feedback)]
    period_ms = 1000 // profile.config.feedback_hz
    assert len(feedback) >= 250 // period_ms, f"{len(feedback)} FEEDBACK in 0.3 s at {profile.config.feedback_hz} Hz"
    assert all(f.boot_id == identity.boot_id for f in feedback)

    levels: dict[str, int] = {}
    regs: dict[int, int] = {}
    for line in lines:
        words = line.split()
        if words[:1] == ["PIN"]:
            levels[words[2]] = int(words[3])
        elif words[:1] == ["REG"]:
            regs[int(words[1], 0)] = int(words[2])
    expected = {pin: level for pin, level in pins.items() if level is not None}
    assert {pin: levels.get(pin, 0) for pin in expected} == expected
    if name == "AckermannPiCar":
        # Disarmed: ESC at neutral, steering at centre, both from Timer1 in hardware.
        cfg = profile.config
        centre_us = cfg.servo_min_us + cfg.steering_center_cdeg * (cfg.servo_max_us - cfg.servo_min_us) // 18000
        assert regs[0x80] & 0b10100000 == 0b10100000  # both channels on the timer
        assert regs[0x88] | regs[0x89] << 8 == 2 * cfg.esc_neutral_us - 1
        assert regs[0x8A] | regs[0x8B] << 8 == 2 * centre_us - 1
