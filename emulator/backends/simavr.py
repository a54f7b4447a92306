"""Firmware in the loop: the compiled AVR firmware (an example's ELF) in simavr, closing the loop
through its pins with the emulator's plant.

    robot = SimavrRobot("diffdrive-tb6612")          # builds the harness and the ELF when needed
    robot.host_write(encode_frame(messages.Ping(1), seq=0))
    robot.advance_us(20_000)
    reply = robot.host_read()
    robot.truth.x_m, robot.truth.encoder_edges       # ground truth from the plant

Two processes cooperate: the C harness (tools/simavr/fil_harness.c) runs the ELF in simavr and
reports, every step, the timer compare and port registers of the motor driver, servo and LED pins
and the bytes UART0 sent; this module decodes those registers into what the board's wires carry
(duty, direction, brake/coast, pulse widths), steps `emulator.plant.Plant` (the same equations and
profiles as the Python emulator) every `PHYSICS_US`, and hands the harness the encoder positions
the plant reached (the harness turns each count change into quadrature edges on the encoder pins)
and the host's bytes, paced at the baud rate. Time is virtual: simavr's cycle counter, 16 per us.

`serve()` paces the same loop to the wall clock behind a pseudo-terminal for `roverlink emulate
--backend simavr`; opening the port resets the MCU after the board's bootloader time (DTR).
"""

from __future__ import annotations

import contextlib
import math
import os
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, TextIO

from emulator.plant.motor import DriveMode
from emulator.plant.plant import WHEEL_CHANNELS, Plant
from emulator.profiles import EmulatorProfile, get_profile

ROOT = Path(__file__).resolve().parents[2]
HARNESS_DIR = ROOT / "tools" / "simavr"
BUILD_DIR = Path(os.environ.get("ROVERLINK_SIMAVR_BUILD", ROOT / "build" / "simavr"))
HARNESS = BUILD_DIR / "fil_harness"
PHYSICS_US = 1000
CYCLES_PER_US = 16
BAUD = 115200
BITS_PER_BYTE = 10


class SimavrError(RuntimeError):
    """The harness or the firmware could not be built, started, or stopped unexpectedly."""


# -- the boards: which registers carry which wire --------------------------------------------------
@dataclass(frozen=True)
class PwmPin:
    """An analogWrite() pin: the timer's TCCRnA (COM bit says the PWM is connected) and OCRnx, or the
    PORT bit when analogWrite(0/255) / digitalWrite() made it a plain output."""

    tccr_a: int
    com_bit: int
    ocr: int
    port: int
    bit: int


@dataclass(frozen=True)
class PortPin:
    port: int
    bit: int


@dataclass(frozen=True)
class Tb6612Channel:
    pwm: PwmPin
    in1: PortPin
    in2: PortPin
    standby: PortPin


@dataclass(frozen=True)
class Bts7960Channel:
    rpwm: PwmPin
    lpwm: PwmPin
    r_en: PortPin
    l_en: PortPin


@dataclass(frozen=True)
class PulsePin:
    """A Timer1 fast-PWM mode 14 servo channel: high for OCR1x + 1 half-microseconds (rc_pulses.h)."""

    tccr_a: int
    com_bit: int
    ocr: int


@dataclass(frozen=True)
class BoardWiring:
    example: str
    mcu: str
    encoders: tuple[tuple[str, str], ...]
    tb6612: tuple[Tb6612Channel, ...] = ()
    bts7960: tuple[Bts7960Channel, ...] = ()
    esc: PulsePin | None = None
    servo: PulsePin | None = None
    leds: tuple[PortPin, ...] = ()
    pcint_k: bool = False

    def watch(self) -> list[int]:
        """Data-space addresses the harness reports; 16-bit registers as two bytes."""
        out: list[int] = []
        for ch in self.tb6612:
            out += [*_pwm_regs(ch.pwm), ch.in1.port, ch.in2.port, ch.standby.port]
        for b in self.bts7960:
            out += [*_pwm_regs(b.rpwm), *_pwm_regs(b.lpwm), b.r_en.port, b.l_en.port]
        for p in (self.esc, self.servo):
            if p is not None:
                out += [p.tccr_a, p.ocr, p.ocr + 1]
        out += [led.port for led in self.leds]
        return sorted(set(out))


def _pwm_regs(p: PwmPin) -> list[int]:
    return [p.tccr_a, p.ocr, p.port]


# ATmega2560 data-space addresses.
_PORTA, _PORTC, _PORTE, _PORTH = 0x22, 0x28, 0x2E, 0x102
_TCCR3A, _OCR3B, _OCR3C = 0x90, 0x9A, 0x9C
_TCCR4A, _OCR4A, _OCR4B = 0xA0, 0xA8, 0xAA
# ATmega328P.
_TCCR1A, _OCR1A, _OCR1B = 0x80, 0x88, 0x8A
_COM_A, _COM_B, _COM_C = 7, 5, 3

WIRING: dict[str, BoardWiring] = {
    # docs/firmware.md, "Boards, wiring and flashing".
    "DiffDriveTB6612": BoardWiring(
        example="DiffDriveTB6612",
        mcu="atmega2560",
        encoders=(("E4", "E5"), ("D3", "D2")),  # pins 2/3 (INT4/5), 18/19 (INT3/2)
        tb6612=(
            Tb6612Channel(
                PwmPin(_TCCR4A, _COM_A, _OCR4A, _PORTH, 3), PortPin(_PORTA, 0), PortPin(_PORTA, 1), PortPin(_PORTA, 4)
            ),
            Tb6612Channel(
                PwmPin(_TCCR4A, _COM_B, _OCR4B, _PORTH, 4), PortPin(_PORTA, 2), PortPin(_PORTA, 3), PortPin(_PORTA, 4)
            ),
        ),
        # Lights bits: front left, front right, rear left, rear right = pins 30..33 = PC7..PC4.
        leds=(PortPin(_PORTC, 7), PortPin(_PORTC, 6), PortPin(_PORTC, 5), PortPin(_PORTC, 4)),
    ),
    "DiffDriveBTS7960": BoardWiring(
        example="DiffDriveBTS7960",
        mcu="atmega2560",
        encoders=(("K0", "K1"), ("K2", "K3")),  # A8/A9, A10/A11 on PCINT2
        bts7960=(
            Bts7960Channel(
                PwmPin(_TCCR3A, _COM_B, _OCR3B, _PORTE, 4),
                PwmPin(_TCCR3A, _COM_C, _OCR3C, _PORTE, 5),
                PortPin(_PORTA, 0),
                PortPin(_PORTA, 1),
            ),
            Bts7960Channel(
                PwmPin(_TCCR4A, _COM_A, _OCR4A, _PORTH, 3),
                PwmPin(_TCCR4A, _COM_B, _OCR4B, _PORTH, 4),
                PortPin(_PORTA, 2),
                PortPin(_PORTA, 3),
            ),
        ),
        pcint_k=True,
    ),
    "AckermannPiCar": BoardWiring(
        example="AckermannPiCar",
        mcu="atmega328p",
        encoders=(("D2", "D3"),),  # INT0 / INT1
        esc=PulsePin(_TCCR1A, _COM_A, _OCR1A),
        servo=PulsePin(_TCCR1A, _COM_B, _OCR1B),
    ),
}


@dataclass(frozen=True)
class PinState:
    """What the MCU's pins tell the hardware around it, decoded from one register snapshot."""

    duty: tuple[float, ...]
    """Signed duty per DC motor channel, -1..1 (PWM duty in the driven direction)."""
    mode: tuple[DriveMode, ...]
    esc_us: int
    """0: no pulses."""
    servo_us: int
    leds: int
    """roverlink::Lights bits."""

    def effort_permille(self, wheel: int) -> int:
        return round(self.duty[wheel] * 1000) if wheel < len(self.duty) else 0


def decode_pins(wiring: BoardWiring, regs: dict[int, int]) -> PinState:
    def bit(p: PortPin) -> bool:
        return bool(regs[p.port] >> p.bit & 1)

    def pwm(p: PwmPin) -> float:
        if regs[p.tccr_a] >> p.com_bit & 1:
            return regs[p.ocr] / 255.0
        return 1.0 if regs[p.port] >> p.bit & 1 else 0.0

    def pulse(p: PulsePin | None) -> int:
        if p is None or not regs[p.tccr_a] >> p.com_bit & 1:
            return 0
        return (regs[p.ocr] | regs[p.ocr + 1] << 8) + 1 >> 1

    duty: list[float] = []
    mode: list[DriveMode] = []
    for ch in wiring.tb6612:
        in1, in2, d = bit(ch.in1), bit(ch.in2), pwm(ch.pwm)
        if not bit(ch.standby) or (not in1 and not in2):
            duty.append(0.0)
            mode.append(DriveMode.COAST)
        elif in1 and in2:
            duty.append(0.0)
            mode.append(DriveMode.BRAKE)
        else:
            duty.append(d if in1 else -d)
            mode.append(DriveMode.DRIVE)
    for b in wiring.bts7960:
        r, left = pwm(b.rpwm), pwm(b.lpwm)
        if not (bit(b.r_en) and bit(b.l_en)):
            duty.append(0.0)
            mode.append(DriveMode.COAST)
        elif r == 0.0 and left == 0.0:
            duty.append(0.0)
            mode.append(DriveMode.BRAKE)
        else:
            duty.append(r - left)
            mode.append(DriveMode.DRIVE)
    leds = 0
    for i, led in enumerate(wiring.leds):
        if bit(led):
            leds |= 1 << i
    return PinState(tuple(duty), tuple(mode), pulse(wiring.esc), pulse(wiring.servo), leds)


# -- building ----------------------------------------------------------------------------------------
def build_harness() -> Path:
    """`make -C tools/simavr` (a no-op when up to date)."""
    result = subprocess.run(
        ["make", "-s", "-C", str(HARNESS_DIR), f"BUILD={BUILD_DIR}"], capture_output=True, text=True, check=False
    )
    if result.returncode != 0:
        raise SimavrError(f"building the simavr harness failed:\n{result.stdout}\n{result.stderr}")
    return HARNESS


def build_elf(example: str) -> Path:
    """The example's ELF, built with the public build tool (cached by content). With the environment
    variable ROVERLINK_SIMAVR_ELF_DIR set, <dir>/<example>/<example>.elf is used instead (an ELF
    built elsewhere, e.g. from another checkout)."""
    from host_sdk import firmware  # noqa: PLC0415 (the build tool only when building)

    prebuilt = os.environ.get("ROVERLINK_SIMAVR_ELF_DIR")
    if prebuilt:
        elf = Path(prebuilt) / example / f"{example}.elf"
        if not elf.is_file():
            raise SimavrError(f"ROVERLINK_SIMAVR_ELF_DIR={prebuilt}: no {elf}")
        return elf

    try:
        return firmware.build_example(example, out_dir=BUILD_DIR / "elf" / example).elf
    except firmware.FirmwareError as exc:
        raise SimavrError(f"building {example} failed: {exc}") from exc


# -- the harness process -------------------------------------------------------------------------------
class Harness:
    """One fil_harness process: the MCU. Steps are synchronous request/reply over pipes."""

    def __init__(self, wiring: BoardWiring, elf: Path, harness: Path | None = None) -> None:
        exe = harness if harness is not None else build_harness()
        self.wiring = wiring
        self.watch = wiring.watch()
        cmd = [str(exe), wiring.mcu, str(elf)]
        for a, b in wiring.encoders:
            cmd += ["--enc", a, b]
        for addr in self.watch:
            cmd += ["--watch", hex(addr)]
        if wiring.pcint_k:
            cmd.append("--pcint-k")
        self._proc = subprocess.Popen(
            cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, bufsize=1, cwd=ROOT
        )
        while True:
            line = self._readline()
            if line.startswith("READY"):
                break
        self.cycle = 0

    def _readline(self) -> str:
        assert self._proc.stdout is not None
        line = self._proc.stdout.readline()
        if not line:
            raise SimavrError(f"the simavr harness exited (code {self._proc.poll()})")
        return line

    def _ask(self, command: str) -> list[str]:
        assert self._proc.stdin is not None
        self._proc.stdin.write(command + "\n")
        self._proc.stdin.flush()
        reply = self._readline().split()
        if not reply or reply[0] == "ERR":
            raise SimavrError(f"harness refused {command!r}")
        return reply

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[dict[int, int], bytes]:
        """Runs `us` of MCU time; returns the watched registers and the bytes UART0 sent."""
        n = len(self.wiring.encoders)
        reply = self._ask(f"S {us} {' '.join(str(c) for c in counts[:n])} {rx.hex() or '-'}")
        self.cycle = int(reply[1])
        raw = bytes.fromhex(reply[2]) if reply[2] != "-" else b""
        regs = dict(zip(self.watch, raw, strict=True))
        return regs, bytes.fromhex(reply[3]) if reply[3] != "-" else b""

    def reset(self) -> None:
        self._ask("R")

    def rx_stats(self) -> tuple[int, int, int]:
        """(longest UDR0-to-read latency in cycles, bytes read, overruns) since the last call."""
        r = self._ask("C")
        return int(r[1]), int(r[2]), int(r[3])

    def set_loop_marker(self, byte_address: int) -> None:
        """Counts main-loop passes from now on (see `loop_stats`)."""
        self._ask(f"L {byte_address}")

    def loop_stats(self) -> tuple[int, int, int, int]:
        """(passes, cycles, shortest pass, longest pass) since the last call."""
        r = self._ask("M")
        return int(r[1]), int(r[2]), int(r[3]), int(r[4])

    def close(self) -> None:
        if self._proc.poll() is None:
            with contextlib.suppress(SimavrError, BrokenPipeError, OSError):
                self._ask("Q")
            try:
                self._proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        for stream in (self._proc.stdin, self._proc.stdout):
            if stream is not None:
                stream.close()


# -- the robot -------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SimTruth:
    """Ground truth of a firmware-in-the-loop robot."""

    time_us: int
    x_m: float
    y_m: float
    theta_rad: float
    speed_m_s: float
    distance_m: float
    encoder_edges: tuple[int, ...]
    """Edges the plant's encoders produced since power-up (the harness puts them on the pins)."""
    rim_speed_mm_s: tuple[float, ...]
    pins: PinState
    steering_rad: float
    resets: int
    in_reset: bool


class MCU(Protocol):
    """What the plant loop needs from an MCU: the simavr harness, or a native build of the core."""

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[PinState, bytes]: ...

    def reset(self) -> None: ...


class _SimavrMCU:
    def __init__(self, harness: Harness) -> None:
        self.harness = harness

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[PinState, bytes]:
        regs, out = self.harness.step(us, counts, rx)
        return decode_pins(self.harness.wiring, regs), out

    def reset(self) -> None:
        self.harness.reset()


_RELEASED = PinState((0.0, 0.0), (DriveMode.COAST, DriveMode.COAST), 0, 0, 0)


class PlantLoop:
    """The plant around an MCU, on a virtual clock in microseconds.

    Every PHYSICS_US: the plant is stepped with the pins of the last MCU step, then the MCU runs
    PHYSICS_US with the encoder positions the plant reached and the host bytes that reach it in
    that interval (paced at the baud rate). MCU output bytes are delivered to the host at once."""

    def __init__(self, profile: str | EmulatorProfile, mcu: MCU, *, baud: int = BAUD) -> None:
        self.profile = get_profile(profile) if isinstance(profile, str) else profile
        self.plant = Plant(self.profile, PHYSICS_US / 1e6)
        self.mcu = mcu
        self.now_us = 0
        self.pins = _RELEASED
        self._to_mcu = bytearray()
        self._from_mcu = bytearray()
        self._credit = 0.0
        self._bytes_per_step = baud / BITS_PER_BYTE * PHYSICS_US / 1e6
        self.resets = 0
        self._hold_until = 0
        self.bytes_lost_in_reset = 0

    # -- the host's end ------------------------------------------------------------------------------
    def host_write(self, data: bytes) -> None:
        self._to_mcu += data

    def host_read(self) -> bytes:
        out = bytes(self._from_mcu)
        self._from_mcu.clear()
        return out

    # -- time --------------------------------------------------------------------------------------------
    def advance_us(self, us: int) -> None:
        self.advance_to_us(self.now_us + us)

    def advance_to_us(self, t_us: int) -> None:
        while self.now_us + PHYSICS_US <= t_us:
            self._step()

    def run_until(self, predicate: Callable[[], bool], timeout_us: int) -> bool:
        deadline = self.now_us + timeout_us
        while not predicate():
            if self.now_us >= deadline:
                return False
            self._step()
        return True

    def _step(self) -> None:
        self._apply(self.pins)
        self.plant.step(self.now_us)
        self.now_us += PHYSICS_US
        self._credit = min(self._credit + self._bytes_per_step, 2 * self._bytes_per_step)
        n = min(int(self._credit), len(self._to_mcu))
        rx = bytes(self._to_mcu[:n])
        del self._to_mcu[:n]
        self._credit -= n
        if self.now_us <= self._hold_until:  # in reset / bootloader: pins released, bytes lost
            self.bytes_lost_in_reset += len(rx)
            self.pins = _RELEASED
            if self.now_us == self._hold_until:
                self.mcu.reset()
            return
        counts = self.plant.encoder_counts()
        self.pins, out = self.mcu.step(PHYSICS_US, counts[:WHEEL_CHANNELS], rx)
        self._from_mcu += out

    def _apply(self, pins: PinState) -> None:
        plant = self.plant
        if plant.esc is None:
            for w, unit in enumerate(plant.units):
                if w < len(pins.duty):
                    unit.motor.command(pins.duty[w], pins.mode[w])
        plant.esc_pulse(pins.esc_us)
        plant.steering_pulse(pins.servo_us)
        plant.lights(pins.leds)

    # -- resets --------------------------------------------------------------------------------------------
    def reset_mcu(self, hold_ms: int = 0) -> None:
        """The reset pin: held for `hold_ms` (the bootloader's time after a DTR reset), then the sketch
        starts again. RAM and outputs are lost, the EEPROM and the encoders' positions are kept."""
        self.resets += 1
        self.pins = _RELEASED
        self._to_mcu.clear()
        if hold_ms <= 0:
            self.mcu.reset()
        else:
            self._hold_until = self.now_us + hold_ms * 1000

    def dtr_reset(self) -> None:
        self.reset_mcu(self.profile.plant.timing.bootloader_ms)

    # -- truth ---------------------------------------------------------------------------------------------
    @property
    def truth(self) -> SimTruth:
        v = self.plant.vehicle
        r = self.profile.wheel_radius_m
        servo = self.plant.servo
        return SimTruth(
            time_us=self.now_us,
            x_m=v.x_m,
            y_m=v.y_m,
            theta_rad=v.theta_rad,
            speed_m_s=v.v_m_s,
            distance_m=v.distance_m,
            encoder_edges=tuple(self.plant.encoder_counts()),
            rim_speed_mm_s=tuple(u.omega_rad_s * r * 1000 for u in self.plant.units),
            pins=self.pins,
            steering_rad=servo.wheel_angle_rad if servo is not None else 0.0,
            resets=self.resets,
            in_reset=self.now_us < self._hold_until,
        )


class SimavrRobot(PlantLoop):
    """A reference robot's example ELF in simavr with the profile's plant around it."""

    def __init__(
        self,
        profile: str = "diffdrive-tb6612",
        *,
        elf: Path | None = None,
        harness: Path | None = None,
        baud: int = BAUD,
    ) -> None:
        prof = get_profile(profile)
        wiring = WIRING[prof.robot.example]
        self.elf = elf if elf is not None else build_elf(wiring.example)
        self.harness = Harness(wiring, self.elf, harness)
        super().__init__(prof, _SimavrMCU(self.harness), baud=baud)

    @property
    def mcu_cycles(self) -> int:
        return self.harness.cycle

    def close(self) -> None:
        self.harness.close()

    def __enter__(self) -> SimavrRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


# -- real time, behind a pseudo-terminal -------------------------------------------------------------------
class Endpoint(Protocol):
    name: str

    def poll(self) -> tuple[bool, int]: ...

    def on_connect(self) -> None: ...

    def read(self) -> bytes: ...

    def write(self, data: bytes) -> None: ...

    def wait(self, timeout_s: float) -> None: ...


def serve(
    robot: PlantLoop,
    endpoint: Endpoint,
    stop: Callable[[], bool],
    *,
    dtr_reset_on_open: bool = True,
    speed: float = 1.0,
    log: TextIO | None = sys.stderr,
) -> float:
    """Keeps the robot's virtual time at wall time x `speed`; returns the achieved ratio of simulated
    to wall time while busy (how much faster than real time the loop can run)."""
    wall0 = time.monotonic()
    virt0 = robot.now_us
    connected = False
    busy_s = 0.0
    lag_warned = False
    while not stop():
        now_connected, opens = endpoint.poll()
        if opens:
            endpoint.on_connect()
            robot.host_read()
            _say(log, f"host connected to {endpoint.name}")
            if dtr_reset_on_open:
                robot.dtr_reset()
        elif connected and not now_connected:
            _say(log, f"host disconnected from {endpoint.name}")
        connected = now_connected
        if connected:
            data = endpoint.read()
            if data:
                robot.host_write(data)
        target = virt0 + int((time.monotonic() - wall0) * 1e6 * speed)
        if target > robot.now_us:
            t0 = time.monotonic()
            robot.advance_to_us(target)
            busy_s += time.monotonic() - t0
            behind = (time.monotonic() - wall0) * 1e6 * speed - (robot.now_us - virt0)
            if behind > 200_000 and not lag_warned:
                lag_warned = True
                _say(log, f"warning: {behind / 1000:.0f} ms behind real time (CPU too slow?)")
        out = robot.host_read()
        if connected and out:
            endpoint.write(out)
        endpoint.wait(0.001 if connected else 0.01)
    simulated_s = (robot.now_us - virt0) / 1e6
    return simulated_s / busy_s if busy_s > 0 else math.inf


def _say(log: TextIO | None, text: str) -> None:
    if log is not None:
        print(f"[simavr] {text}", file=log, flush=True)
