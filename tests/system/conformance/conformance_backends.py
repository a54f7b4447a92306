"""One small test-facing interface over the three firmware backends, and a host end for scenarios.

* ``python``: the Python firmware model (``emulator.Emulator``), its own plant.
* ``native``: the C++ core built natively (``tests/support/native_sim.py``, ctypes), with the
  emulator's plant closing the loop every 1 ms through ``emulator.backends.simavr.PlantLoop``.
* ``simavr``: the example's ELF in simavr (``emulator.backends.simavr.SimavrRobot``), the same
  plant, the encoders as quadrature edges on the pins.
* ``rp2040``: the robot moved to a Pico (its drive on the Pico pinout), its firmware's flash image
  in rp2040js (``emulator.backends.rp2040.Rp2040Robot``), the same plant. Its profile is named
  ``NAME@pico``, and the reference for it is the Python model of that same Pico robot (the board
  and its capabilities are in IDENTITY's bytes).

Each backend: ``write(bytes)``, ``advance_us(us)``, ``read() -> bytes``, ``reset()`` (the reset
pin, with the board's bootloader time), ``now_us``, ``truth()`` (pose and encoder edges from
the plant), ``pins()`` (what the ESC, servo and LED pins carry now: the plant's inputs for the
Python model, the core's recorded outputs for the native build, the decoded registers for simavr)
and ``disconnect_encoder(wheel)`` (the plant's encoder stops producing edges). ``make_backend(...,
eeprom=image)`` starts the board with those bytes at EEPROM address 0 before its first boot (the
native core boots again after the poke; simavr loads them from an ``.eeprom`` section added to a
copy of the ELF, ``emulator.backends.simavr.elf_with_eeprom``). Everything runs on virtual time:
no sleeps, deterministic for a given input.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from emulator import Emulator
from emulator.backends.rp2040 import Rp2040Robot, pico_profile, pico_robot
from emulator.backends.simavr import PinState, PlantLoop, SimavrRobot, elf_with_eeprom
from emulator.profiles import EmulatorProfile
from host_sdk.framing import encode_frame
from protocol.codec.message import Message
from protocol.generated.hardware import MotorMode
from protocol.generated.profiles import PROFILES
from roverlink.firmware import BUILD_ROOT
from roverlink.firmware.pico import build_pico
from tests.support.hostlink import Link, answers
from tests.support.native_sim import NativeSim
from tests.support.simavr import example_elf

BACKENDS = ("python", "native", "simavr", "rp2040")
"""The suite's backends. make_backend() also opens "rp2040" (the robot moved to a Pico in rp2040js),
which is not in the suite yet: docs/emulator.md, "The rp2040 backend", lists what it passes."""
ON_PICO = "@pico"


def on_board(backend_name: str, profile: str) -> str:
    """The profile `backend_name` runs `profile` as: NAME@pico on the rp2040 backend."""
    return profile + ON_PICO if backend_name == "rp2040" and not profile.endswith(ON_PICO) else profile


def base_profile(profile: str) -> str:
    """The reference robot a backend's profile is (NAME for NAME@pico)."""
    return profile.removesuffix(ON_PICO)


def _profile(profile: str) -> str | EmulatorProfile:
    return pico_profile(profile.removesuffix(ON_PICO)) if profile.endswith(ON_PICO) else profile


@dataclass(frozen=True)
class Truth:
    time_us: int
    x_m: float
    y_m: float
    theta_rad: float
    encoder_edges: tuple[int, ...]


@dataclass(frozen=True)
class Pins:
    """What the board's pulse and LED pins carry at one instant (ground truth, not FEEDBACK)."""

    esc_us: int
    """0: no pulses."""
    servo_us: int
    leds: int
    """roverlink::Lights bits."""


class Backend(Protocol):
    name: str
    profile: str

    @property
    def now_us(self) -> int: ...

    def write(self, data: bytes) -> None: ...

    def advance_us(self, us: int) -> None: ...

    def read(self) -> bytes: ...

    def reset(self) -> None: ...

    def truth(self) -> Truth: ...

    def pins(self) -> Pins: ...

    def disconnect_encoder(self, wheel: int, disconnected: bool = True) -> None: ...

    def close(self) -> None: ...


class PythonBackend:
    def __init__(self, profile: str, seed: int = 1, eeprom: bytes | None = None) -> None:
        self.name = "python"
        self.profile = profile
        # The board id the example reports, so IDENTITY compares byte for byte; no adapter latency.
        prof = _profile(profile)
        board = prof.robot.board if isinstance(prof, EmulatorProfile) else PROFILES[profile].board
        self.emu = Emulator(prof, seed, latency_us=0, board_id=board)
        if eeprom is not None:
            assert self.emu.firmware is None  # the sketch starts after power_on_ms: not booted yet
            self.emu.eeprom[: len(eeprom)] = eeprom

    @property
    def now_us(self) -> int:
        return self.emu.now_us

    def write(self, data: bytes) -> None:
        self.emu.host_write(data)

    def advance_us(self, us: int) -> None:
        self.emu.advance_us(us)

    def read(self) -> bytes:
        return self.emu.host_read()

    def reset(self) -> None:
        self.emu.reset_mcu()

    def truth(self) -> Truth:
        p = self.emu.truth.plant
        return Truth(self.emu.now_us, p.x_m, p.y_m, p.theta_rad, tuple(w.encoder_edges for w in p.wheels))

    def pins(self) -> Pins:
        plant = self.emu.plant
        esc = plant.esc.pulse_us if plant.esc is not None else 0
        servo = plant.servo.pulse_us if plant.servo is not None else 0
        return Pins(esc, servo, plant.leds.mask)

    def disconnect_encoder(self, wheel: int, disconnected: bool = True) -> None:
        self.emu.disconnect_encoder(wheel, disconnected)

    def close(self) -> None:
        pass


class _NativeMCU:
    """The native core as the MCU of a PlantLoop: encoders from the plant, outputs to it."""

    def __init__(self, profile: str, seed: int) -> None:
        self.sim = NativeSim(profile, seed)
        self._base: list[int] | None = [0, 0]

    def step(self, us: int, counts: list[int], rx: bytes) -> tuple[PinState, bytes]:
        if self._base is None:  # counters start from 0 at a boot; the wheels are where they are
            self._base = list(counts)
        for w, c in enumerate(counts):
            self.sim.set_encoder(w, c - self._base[w])
        self.sim.feed(rx)
        self.sim.advance_us(us)
        out = self.sim.outputs()
        duty = tuple(e / 1000 for e in out.motor_effort)
        mode = tuple(MotorMode(int(m)) for m in out.motor_mode)
        return PinState(duty, mode, out.esc_us, out.steering_us, int(out.lights)), self.sim.read()

    def reset(self) -> None:
        self.sim.reset()
        self._base = None


class NativeBackend:
    def __init__(self, profile: str, seed: int = 1, eeprom: bytes | None = None) -> None:
        self.name = "native"
        self.profile = profile
        self.mcu = _NativeMCU(profile, seed)
        if eeprom is not None:
            self.mcu.sim.read()  # the first boot's bytes: dropped, as if it never happened
            self.mcu.sim.eeprom_write(0, eeprom)
            self.mcu.reset()  # boot again on that EEPROM
        self.loop = PlantLoop(profile, self.mcu)

    @property
    def now_us(self) -> int:
        return self.loop.now_us

    def write(self, data: bytes) -> None:
        self.loop.host_write(data)

    def advance_us(self, us: int) -> None:
        self.loop.advance_us(us)

    def read(self) -> bytes:
        return self.loop.host_read()

    def reset(self) -> None:
        self.loop.dtr_reset()

    def truth(self) -> Truth:
        t = self.loop.truth
        return Truth(t.time_us, t.x_m, t.y_m, t.theta_rad, t.encoder_edges)

    def pins(self) -> Pins:
        p = self.loop.pins
        return Pins(p.esc_us, p.servo_us, p.leds)

    def disconnect_encoder(self, wheel: int, disconnected: bool = True) -> None:
        self.loop.disconnect_encoder(wheel, disconnected)

    def close(self) -> None:
        self.mcu.sim.close()


class _FirmwareBackend:
    """A compiled firmware in a chip emulator inside the plant loop (simavr, rp2040js)."""

    name: str
    profile: str
    robot: SimavrRobot | Rp2040Robot

    @property
    def now_us(self) -> int:
        return self.robot.now_us

    def write(self, data: bytes) -> None:
        self.robot.host_write(data)

    def advance_us(self, us: int) -> None:
        self.robot.advance_us(us)

    def read(self) -> bytes:
        return self.robot.host_read()

    def reset(self) -> None:
        self.robot.dtr_reset()

    def truth(self) -> Truth:
        t = self.robot.truth
        return Truth(t.time_us, t.x_m, t.y_m, t.theta_rad, t.encoder_edges)

    def pins(self) -> Pins:
        p = self.robot.pins
        return Pins(p.esc_us, p.servo_us, p.leds)

    def disconnect_encoder(self, wheel: int, disconnected: bool = True) -> None:
        self.robot.disconnect_encoder(wheel, disconnected)

    def close(self) -> None:
        self.robot.close()


class SimavrBackend(_FirmwareBackend):
    def __init__(self, profile: str, seed: int = 1, eeprom: bytes | None = None) -> None:
        del seed  # the ELF's boot_id comes from its EEPROM boot counter and ADC noise
        self.name = "simavr"
        self.profile = profile
        elf = example_elf(profile)
        if eeprom is not None:
            elf = elf_with_eeprom(elf, eeprom)
        self.robot = SimavrRobot(profile, elf=elf)


class Rp2040Backend(_FirmwareBackend):
    def __init__(self, profile: str, seed: int = 1, eeprom: bytes | None = None) -> None:
        if eeprom is not None:
            raise ValueError("the Pico keeps no configuration: no EEPROM image to start from")
        self.name = "rp2040"
        self.profile = on_board("rp2040", profile)
        name = self.profile.removesuffix(ON_PICO)
        self.robot = Rp2040Robot(pico_profile(name), pico_image(name), seed=seed)


def pico_image(name: str) -> Path:
    """The flash image of reference robot `name` moved to a Pico (built once, cached by content)."""
    return build_pico(pico_robot(name), BUILD_ROOT / "pico" / name, name=name).bin


def make_backend(name: str, profile: str, seed: int = 1, eeprom: bytes | None = None) -> Backend:
    """`eeprom`: bytes at EEPROM address 0 before the first boot (None: a blank, erased EEPROM)."""
    if name == "python":
        return PythonBackend(profile, seed, eeprom)
    if name == "native":
        return NativeBackend(profile, seed, eeprom)
    if name == "simavr":
        return SimavrBackend(profile, seed, eeprom)
    if name == "rp2040":
        return Rp2040Backend(profile, seed, eeprom)
    raise ValueError(f"unknown backend {name!r}: one of {', '.join(BACKENDS)}")


# -- the host end ----------------------------------------------------------------------------------
class Host(Link):
    """The shared host end over a backend, stepped 1 ms at a time; waits take frames in order of
    arrival (after the previous wait's match), so a scenario sees every frame once."""

    def __init__(self, backend: Backend) -> None:
        super().__init__(backend.write, backend.read, lambda: backend.now_us)
        self.b = backend
        self.cursor = 0
        self.sent_at: dict[int, int] = {}
        self.pin_log: list[tuple[int, Pins]] | None = None
        """Set to a list to sample ``pins()`` after every step (1 ms)."""

    def send(self, msg: Message, seq: int | None = None) -> int:
        seq = super().send(msg, seq)
        self.sent_at[seq] = self.b.now_us
        return seq

    def step(self, us: int = 1000) -> None:
        self.b.advance_us(us)
        self.receive()
        if self.pin_log is not None:
            self.pin_log.append((self.b.now_us, self.b.pins()))

    def run_ms(self, ms: int) -> None:
        for _ in range(ms):
            self.step()

    def wait_for(self, cls: type[Message], timeout_ms: int, pred: object = None) -> tuple[int, Message]:
        """The first frame of `cls` (matching `pred`) after the previous wait's match."""
        for _ in range(timeout_ms + 1):
            for i in range(self.cursor, len(self.received)):
                t, m = self.received[i].time_us, self.received[i].message
                if isinstance(m, cls) and (pred is None or pred(m)):  # type: ignore[operator]
                    self.cursor = i + 1
                    return t, m
            self.step()
        seen = [type(r.message).__name__ for r in self.received[self.cursor :]]
        raise AssertionError(f"{self.b.name}: no {cls.__name__} within {timeout_ms} ms (saw {seen[-12:]})")

    def request(self, msg: Message, seq: int | None = None, timeout_ms: int = 200) -> Message:
        seq = self.send(msg, seq)
        return self.wait_for(Message, timeout_ms, answers(msg, seq))[1]

    def since(self, cls: type[Message], t_us: int) -> list[tuple[int, Message]]:
        return [(t, m) for t, m in self.timed(Message) if t >= t_us and isinstance(m, cls)]


def wire(msg: Message) -> str:
    """The message's frame bytes, with the fields that legitimately differ between boards and runs
    (boot_id, uptime, MCU time) zeroed: what 'identical wire bytes' compares."""
    changes = {f: 0 for f in ("boot_id", "uptime_ms", "mcu_time_us") if hasattr(msg, f)}
    return encode_frame(dataclasses.replace(msg, **changes) if changes else msg, 0).hex()  # type: ignore[type-var]
