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
and the host's bytes. Time is virtual: simavr's cycle counter, 16 per us. Between the host and the
MCU is the Python emulator's serial line (`emulator.line.SerialLink`: pacing, latency, faults, the
bootloader's garbage), and fault specs use its grammar and injection code (`emulator.injection`);
`seed` also draws the board's own randomness (ADC0 noise, EEPROM boot counter). docs/emulator.md,
"The simavr backend", lists what is supported and what is refused.

`serve()` paces the same loop to the wall clock behind a pseudo-terminal for `roverlink emulate
--backend simavr`; opening the port resets the MCU after the board's bootloader time (DTR).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import subprocess
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar, Protocol

from emulator.clock import VirtualClock
from emulator.device import ResetKind, saved_eeprom_image
from emulator.errors import EmulatorValueError
from emulator.faults import FaultSpec
from emulator.firmware.config import BOOT_COUNTER_ADDR
from emulator.injection import FaultInjection, checked_board_options
from emulator.line import SerialLink
from emulator.plant.motor import DriveMode
from emulator.plant.plant import WHEEL_CHANNELS, Plant
from emulator.profiles import EmulatorProfile, get_profile
from emulator.rng import Streams
from emulator.truth import FaultRecord, LineTruth
from protocol.framing import Frame, FrameDecoder
from protocol.generated.enums import IdentityReason
from protocol.generated.messages import Identity

ROOT = Path(__file__).resolve().parents[2]
HARNESS_DIR = ROOT / "tools" / "simavr"
BUILD_DIR = Path(os.environ.get("ROVERLINK_SIMAVR_BUILD", ROOT / "build" / "simavr"))
HARNESS = BUILD_DIR / "fil_harness"
PHYSICS_US = 1000
CYCLES_PER_US = 16
BAUD = 115200
BITS_PER_BYTE = 10
HANDLER_FLAG = 0x1000000  # profile keys of PCs run inside a handler boundary (Harness.profile_handler)


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


def prebuilt_elf(example: str) -> Path:
    """The example's ELF from the folder ROVERLINK_SIMAVR_ELF_DIR names (<dir>/<example>/<example>.elf),
    for a SimavrRobot made without `elf=`. Building is the tools' job (`roverlink firmware build`,
    roverlink.firmware.build_example): the emulator runs a firmware, it does not compile one."""
    prebuilt = os.environ.get("ROVERLINK_SIMAVR_ELF_DIR")
    if not prebuilt:
        raise SimavrError(
            f"no ELF for {example}: pass elf= (e.g. roverlink.firmware.build_example({example!r}).elf) "
            "or set ROVERLINK_SIMAVR_ELF_DIR to a folder holding <example>/<example>.elf"
        )
    elf = Path(prebuilt) / example / f"{example}.elf"
    if not elf.is_file():
        raise SimavrError(f"ROVERLINK_SIMAVR_ELF_DIR={prebuilt}: no {elf}")
    return elf


# -- the harness process -------------------------------------------------------------------------------
class Harness:
    """One fil_harness process: the MCU. Steps are synchronous request/reply over pipes."""

    def __init__(
        self,
        wiring: BoardWiring,
        elf: Path,
        harness: Path | None = None,
        *,
        adc0_mv: int | None = None,
        line_ppb: int = 0,
    ) -> None:
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
        if adc0_mv is not None:
            cmd += ["--adc0", str(adc0_mv)]
        if line_ppb:
            cmd += ["--line-ppb", str(line_ppb)]  # the host's bytes, in the drifting MCU's cycles
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

    def profile_function(self, byte_address: int) -> None:
        """Profiles the calls of the function at that address from now on, interrupt handlers
        excluded (see `profile`); 0 stops."""
        self._ask(f"P {byte_address}")

    def profile_handler(self, byte_address: int) -> None:
        """Inside profiled calls, the cycles of calls of the function at that address are kept
        apart: `profile` reports them at PC + HANDLER_FLAG (0 clears every handler)."""
        self._ask(f"H {byte_address}")

    def profile(self) -> tuple[int, int, int, int, dict[int, int]]:
        """(calls, cycles, cheapest call, longest call less its handlers' cycles, cycles per PC byte
        address) since the last call."""
        r = self._ask("D")
        per_pc = {} if r[5] == "-" else {int(a, 16): int(c) for a, c in (t.split(":") for t in r[5:])}
        return int(r[1]), int(r[2]), int(r[3]), int(r[4]), per_pc

    def longest_call(self) -> int:
        """The longest profiled call since the last call of this, in cycles from its entry to its
        return (interrupts and handlers included: how long it held the main loop)."""
        return int(self._ask("W")[1])

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
    stalled: tuple[bool, ...] = ()
    encoder_connected: tuple[bool, ...] = ()
    bytes_lost_in_reset: int = 0
    """Host bytes that reached the MCU while it was in reset or in its bootloader."""
    host_to_mcu: LineTruth | None = None
    mcu_to_host: LineTruth | None = None
    faults: tuple[FaultRecord, ...] = ()
    """Every fault with the virtual time it took effect (as `Emulator.truth.faults`)."""
    boot_ids: tuple[int, ...] = ()
    """boot_id of every boot so far, oldest first: read from the boot IDENTITY the firmware sent
    (its UART output, before the line), as `Emulator.truth.mcu.boot_ids`."""


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


class PlantLoop(FaultInjection):
    """The plant around an MCU, on a virtual clock in microseconds, behind the emulator's serial line.

    Every PHYSICS_US: the plant is stepped with the pins of the last MCU step, then the MCU runs
    PHYSICS_US of its own time (more or less with `drift_ppm`) with the encoder positions the plant
    reached and the host bytes that reach it in that interval. Both directions go through the Python
    emulator's `SerialLink` (emulator/line.py): baud pacing, `latency_us`, the line faults of a fault
    spec drawn from `seed`, the bootloader's garbage after an external or DTR reset and the break
    when the sketch starts. Host bytes that arrive while the MCU is in reset or in its bootloader are
    lost. Fault items are scheduled on `clock` (emulator/injection.py); see UNSUPPORTED_FAULTS."""

    UNSUPPORTED_FAULTS: ClassVar[dict[str, str]] = {
        "eeprom": "not available with --backend simavr: simavr programs every EEPROM cell the firmware "
        "writes (it has no failing-cell model), so a write cannot be made to fail",
    }

    def __init__(
        self,
        profile: str | EmulatorProfile,
        mcu: MCU,
        *,
        baud: int = BAUD,
        seed: int = 0,
        faults: str | FaultSpec | None = None,
        latency_us: int = 0,
        drift_ppm: float = 0.0,
        bootloader_ms: int | None = None,
    ) -> None:
        self.profile = get_profile(profile) if isinstance(profile, str) else profile
        self.bootloader_ms = checked_board_options(self.profile, latency_us, drift_ppm, bootloader_ms)
        self.plant = Plant(self.profile, PHYSICS_US / 1e6)
        self.mcu = mcu
        self.now_us = 0
        self.clock = VirtualClock()
        self.seed = seed
        self.streams = Streams(seed)
        self.faults: list[FaultRecord] = []
        self.faults_dropped = 0
        self.link = SerialLink(self.streams, baud, latency_us, log=self._log)
        self.h2m = self.link.h2m
        self.m2h = self.link.m2h
        self.pins = _RELEASED
        self._drift_ppb = round(drift_ppm * 1000)
        self._mcu_steps = 0
        self._mcu_us = 0
        self.resets = 0
        self._restart_at: int | None = None
        self.bytes_lost_in_reset = 0
        # The firmware's own output, decoded before the line: the boot_id is the firmware's to draw.
        self.boot_ids: list[int] = []
        self._tx_frames = FrameDecoder()
        # Power-on: the sketch runs from the first step (no bootloader); its UART start is a break.
        self.link.sketch_started(0)
        self.apply_faults(faults or FaultSpec())

    # -- the host's end ------------------------------------------------------------------------------
    def host_write(self, data: bytes) -> None:
        """Bytes from the host, sent now; they reach the MCU after pacing and latency."""
        self.h2m.send(bytes(data), self.now_us)

    def host_read(self) -> bytes:
        """Every byte from the MCU that has reached the host by now."""
        return self.m2h.receive(self.now_us)

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
        start = self.now_us
        self._apply(self.pins)
        self.plant.step(start)
        end = self.now_us = start + PHYSICS_US
        # The bytes whose start bit reaches the MCU in this step: its UART (the harness's receive
        # model) takes them from there at the baud rate.
        rx = self.h2m.receive(end + int(self.h2m.byte_time_us))
        if self._restart_at is not None:  # in reset / bootloader: pins released, bytes lost
            self.bytes_lost_in_reset += len(rx)
            self.pins = _RELEASED
            if end >= self._restart_at:
                self._restart_at = None
                self.mcu.reset()
                self._tx_frames.reset()  # a frame cut by the reset is not the new boot's
                self.bytes_lost_in_reset += self.link.sketch_started(end)
        else:
            counts = self.plant.encoder_counts()
            self.pins, out = self.mcu.step(self._mcu_step_us(), counts[:WHEEL_CHANNELS], rx)
            if out:
                self.m2h.send_paced(out, end)  # the MCU's UART paced them during the step
                self._note_boots(out)
        self.clock.advance_to(end)  # fault items due by now

    def _note_boots(self, out: bytes) -> None:
        for item in self._tx_frames.feed(out):
            if (
                isinstance(item, Frame)
                and isinstance(item.message, Identity)
                and item.message.reason is IdentityReason.BOOT
            ):
                self.boot_ids.append(item.message.boot_id)

    def _mcu_step_us(self) -> int:
        """MCU microseconds in this step: PHYSICS_US, times 1 + drift_ppm / 1e6 on average."""
        if not self._drift_ppb:
            return PHYSICS_US
        self._mcu_steps += 1
        total = self._mcu_steps * PHYSICS_US * (1_000_000_000 + self._drift_ppb) // 1_000_000_000
        us, self._mcu_us = total - self._mcu_us, total
        return us

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
    def _begin_reset(self, kind: ResetKind, hold_us: int) -> None:
        """RAM and outputs are lost, the EEPROM and the encoders' positions are kept. An external or
        DTR reset runs the bootloader (`bootloader_ms`, garbage on the line); a brown-out holds the
        MCU in reset `hold_us`, then the oscillator starts (`power_on_ms`) and the ESC has lost its
        calibration."""
        now = self.now_us
        self.resets += 1
        self.pins = _RELEASED
        bootloader = kind in (ResetKind.EXTERNAL, ResetKind.DTR)
        self.link.mcu_reset(now, bootloader=bootloader)
        if kind is ResetKind.BROWN_OUT:
            self.plant.power_cycle()
        if bootloader:
            self._restart_at = now + self.bootloader_ms * 1000
        else:
            self._restart_at = now + hold_us + self.profile.plant.timing.power_on_ms * 1000

    def fail_eeprom(self, failing: bool = True) -> None:
        raise SimavrError(f"fail_eeprom: {self.UNSUPPORTED_FAULTS['eeprom']}")

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
            in_reset=self._restart_at is not None,
            stalled=tuple(u.stalled for u in self.plant.units),
            encoder_connected=tuple(u.encoder.connected if u.encoder is not None else False for u in self.plant.units),
            bytes_lost_in_reset=self.bytes_lost_in_reset,
            host_to_mcu=self.h2m.truth(),
            mcu_to_host=self.m2h.truth(),
            faults=tuple(self.faults),
            boot_ids=tuple(self.boot_ids),
        )


class SimavrRobot(PlantLoop):
    """A reference robot's example ELF in simavr with the profile's plant around it.

    `seed` (None: the harness's fixed board) draws what is random on a real board: the ADC0 noise
    the firmware mixes into its boot_id (`--adc0` of the harness) and the EEPROM boot counter it
    starts from, as well as the line's faults and the bootloader's garbage. `eeprom="saved"` starts
    with the profile's defaults saved (the image Python writes, in the C++ core's layout)."""

    def __init__(
        self,
        profile: str = "diffdrive-tb6612",
        *,
        elf: Path | None = None,
        harness: Path | None = None,
        baud: int = BAUD,
        seed: int | None = None,
        faults: str | FaultSpec | None = None,
        latency_us: int = 0,
        drift_ppm: float = 0.0,
        eeprom: str = "blank",
        bootloader_ms: int | None = None,
    ) -> None:
        prof = get_profile(profile)
        if baud != BAUD:
            raise EmulatorValueError(
                "baud", baud, f"{BAUD} with the simavr backend: the example's Serial.begin({BAUD}) is compiled in"
            )
        if eeprom not in ("blank", "saved"):
            raise EmulatorValueError("eeprom", eeprom, "'blank' (a new board) or 'saved' (defaults saved)")
        checked_board_options(prof, latency_us, drift_ppm, bootloader_ms)  # before the harness gets them
        wiring = WIRING[prof.robot.example]
        elf = elf if elf is not None else prebuilt_elf(wiring.example)
        adc0_mv, image = board_randomness(seed)
        if eeprom == "saved":
            address, saved = saved_eeprom_image(prof)
            image = image.ljust(address, b"\xff")[:address] + saved
        self.elf = elf_with_eeprom(elf, image) if image else elf
        self.harness = Harness(wiring, self.elf, harness, adc0_mv=adc0_mv, line_ppb=round(drift_ppm * 1000))
        try:
            super().__init__(
                prof,
                _SimavrMCU(self.harness),
                baud=baud,
                seed=seed or 0,
                faults=faults,
                latency_us=latency_us,
                drift_ppm=drift_ppm,
                bootloader_ms=bootloader_ms,
            )
        except BaseException:
            self.harness.close()
            raise

    @property
    def mcu_cycles(self) -> int:
        return self.harness.cycle

    def close(self) -> None:
        self.harness.close()

    def __enter__(self) -> SimavrRobot:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def board_randomness(seed: int | None) -> tuple[int | None, bytes]:
    """What is random on a real board, drawn from `seed`: the millivolts on the open ADC0 pin and the
    EEPROM boot counter (u32 at BOOT_COUNTER_ADDR, little-endian). None: the harness's fixed ADC0
    and an erased EEPROM (no bytes to load)."""
    if seed is None:
        return None, b""
    rng = Streams(seed).get("simavr:board")
    adc0_mv = rng.randrange(5000)
    counter = rng.getrandbits(32).to_bytes(4, "little")
    return adc0_mv, b"\xff" * BOOT_COUNTER_ADDR + counter


def elf_with_eeprom(elf: Path, eeprom: bytes) -> Path:
    """A copy of `elf` with an `.eeprom` section holding `eeprom` (from address 0): simavr's loader
    programs it into the EEPROM before the first instruction, as avrdude would flash an .eep file.
    Cached under BUILD_DIR by content."""
    key = hashlib.sha256(elf.read_bytes() + b"\0" + eeprom).hexdigest()[:16]
    out = BUILD_DIR / "elf-eeprom" / key / elf.name
    if out.is_file():
        return out
    objcopy = shutil.which("avr-objcopy")
    if objcopy is None:
        raise SimavrError("avr-objcopy (Debian: binutils-avr) is needed to give the ELF an EEPROM image")
    out.parent.mkdir(parents=True, exist_ok=True)
    image = out.with_suffix(".eep.bin")
    image.write_bytes(eeprom)
    tmp = out.with_suffix(f".{os.getpid()}.tmp")
    result = subprocess.run(
        [objcopy, "--add-section", f".eeprom={image}", "--set-section-flags", ".eeprom=contents,data", elf, tmp],
        capture_output=True,
        text=True,
        check=False,
    )
    if result.returncode != 0:
        raise SimavrError(f"avr-objcopy could not add the EEPROM image to {elf}: {result.stderr.strip()}")
    tmp.replace(out)
    return out
