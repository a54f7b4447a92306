"""The RoverLink firmware core, built natively, driven from Python (ctypes).

``make -C tests/firmware/native sim`` builds ``build/native/sim/libroverlink_sim.so``: the C++ core of
``arduino/RoverLink/src/core`` on the native hardware layer (``src/hal/native``: a simulated
clock, encoder counters, recorded outputs, a 1 KB EEPROM) behind the small C ABI documented at the
top of ``tests/firmware/native/core/sim_api.cpp``. This module wraps it:

    from tests.support.native_sim import HostLink, NativeSim
    from host_sdk import messages

    with NativeSim("diffdrive-tb6612", seed=1) as sim:
        host = HostLink(sim)
        host.send(messages.Hello(...))
        frames = host.run(10_000)        # advance 10 ms, decode what the firmware sent
        sim.add_encoder(0, 78)           # your plant moves the wheels
        out = sim.outputs()              # motor efforts, pulses, lights, session state, ...

Nothing runs in real time: the firmware only runs inside ``advance_us`` (one ``poll()`` at the
current time, then one every ``poll_interval_us`` of simulated time), so its control ticks come
exactly every 10 ms of simulated time. The library is built with UndefinedBehaviorSanitizer set to
abort, so undefined behaviour in the core kills the test process instead of passing silently.
"""

from __future__ import annotations

import ctypes
import functools
import os
from dataclasses import dataclass, fields
from pathlib import Path
from types import TracebackType

from protocol.generated.enums import FailsafeReason, FeedbackMode, Status
from protocol.generated.hardware import Lights, MotorMode
from protocol.generated.state_machine import SessionState
from tests.support import make
from tests.support.hostlink import Link, Received

ROOT = Path(__file__).resolve().parents[2]
NATIVE_DIR = ROOT / "tests" / "firmware" / "native"
BUILD_DIR = Path(os.environ.get("ROVERLINK_NATIVE_BUILD", ROOT / "build" / "native"))
LIBRARY = BUILD_DIR / "sim" / "libroverlink_sim.so"
API_VERSION = 1


class SimError(RuntimeError):
    """The simulator library could not be built or loaded, or was asked for something it lacks."""


class _RawOutputs(ctypes.Structure):
    """rl_sim_outputs, field for field (sim_api.cpp)."""

    _fields_ = (
        ("time_us", ctypes.c_uint64),
        ("micros", ctypes.c_uint32),
        ("boot_id", ctypes.c_uint32),
        ("ticks_skipped", ctypes.c_uint32),
        ("duplicates", ctypes.c_uint32),
        ("frames_sent", ctypes.c_uint32),
        ("motor_calls", ctypes.c_uint32 * 2),
        ("encoder", ctypes.c_int32 * 2),
        ("counts", ctypes.c_int32 * 2),
        ("ramped_mm_s", ctypes.c_float * 2),
        ("integral", ctypes.c_float * 2),
        ("motor_effort", ctypes.c_int16 * 2),
        ("motor_mode", ctypes.c_uint8 * 2),
        ("esc_us", ctypes.c_uint16),
        ("steering_us", ctypes.c_uint16),
        ("tick", ctypes.c_uint16),
        ("steering_cdeg", ctypes.c_uint16),
        ("watchdog_ms", ctypes.c_uint16),
        ("target_mm_s", ctypes.c_int16 * 2),
        ("measured_mm_s", ctypes.c_int16 * 2),
        ("effort_permille", ctypes.c_int16 * 2),
        ("lights", ctypes.c_uint8),
        ("state", ctypes.c_uint8),
        ("failsafe_reason", ctypes.c_uint8),
        ("status", ctypes.c_uint8),
        ("feedback_mode", ctypes.c_uint8),
        ("feedback_hz", ctypes.c_uint8),
        ("ack_seq", ctypes.c_uint8),
        ("reserved", ctypes.c_uint8),
    )


@dataclass(frozen=True)
class Outputs:
    """What the board is doing and what the firmware thinks, at one instant."""

    time_us: int
    micros: int
    boot_id: int
    ticks_skipped: int
    duplicates: int
    frames_sent: int
    motor_calls: tuple[int, int]
    encoder: tuple[int, int]
    counts: tuple[int, int]
    ramped_mm_s: tuple[float, float]
    integral: tuple[float, float]
    motor_effort: tuple[int, int]
    motor_mode: tuple[MotorMode, MotorMode]
    esc_us: int
    steering_us: int
    tick: int
    steering_cdeg: int
    watchdog_ms: int
    target_mm_s: tuple[int, int]
    measured_mm_s: tuple[int, int]
    effort_permille: tuple[int, int]
    lights: Lights
    state: SessionState
    failsafe_reason: FailsafeReason
    status: Status
    feedback_mode: FeedbackMode
    feedback_hz: int
    ack_seq: int

    @classmethod
    def _from_raw(cls, raw: _RawOutputs) -> Outputs:
        values: dict[str, object] = {}
        for f in fields(cls):
            value = getattr(raw, f.name)
            if isinstance(value, ctypes.Array):
                value = tuple(value)
            values[f.name] = value
        values["motor_mode"] = tuple(MotorMode(m) for m in raw.motor_mode)
        values["lights"] = Lights(raw.lights)
        values["state"] = SessionState(raw.state)
        values["failsafe_reason"] = FailsafeReason(raw.failsafe_reason)
        values["status"] = Status(raw.status)
        values["feedback_mode"] = FeedbackMode(raw.feedback_mode)
        return cls(**values)  # type: ignore[arg-type]


def build(*, quiet: bool = True) -> Path:
    """Runs ``make -C tests/firmware/native sim`` (a no-op when up to date); returns the library's path."""
    result = make.make(NATIVE_DIR, "sim", build=BUILD_DIR, quiet=quiet)
    if result.returncode != 0:
        raise SimError(f"make sim failed (exit {result.returncode}):\n{result.stdout}\n{result.stderr}")
    return LIBRARY


def _declare(lib: ctypes.CDLL) -> None:
    p, u8, i32, u32, u64, sz = (
        ctypes.c_void_p,
        ctypes.c_uint8,
        ctypes.c_int32,
        ctypes.c_uint32,
        ctypes.c_uint64,
        ctypes.c_size_t,
    )
    buf = ctypes.c_char_p
    signatures: dict[str, tuple[object, list[object]]] = {
        "rl_sim_api_version": (u32, []),
        "rl_sim_outputs_size": (u32, []),
        "rl_sim_profile_count": (ctypes.c_int, []),
        "rl_sim_profile_name": (ctypes.c_char_p, [ctypes.c_int]),
        "rl_sim_profile_example": (ctypes.c_char_p, [ctypes.c_int]),
        "rl_sim_create": (p, [ctypes.c_char_p, u32]),
        "rl_sim_destroy": (None, [p]),
        "rl_sim_reset": (None, [p]),
        "rl_sim_set_poll_interval_us": (None, [p, u32]),
        "rl_sim_set_boot_micros": (None, [p, u32]),
        "rl_sim_feed_host_bytes": (None, [p, buf, sz]),
        "rl_sim_read_mcu_bytes": (sz, [p, ctypes.c_void_p, sz]),
        "rl_sim_mcu_bytes_available": (sz, [p]),
        "rl_sim_advance_us": (None, [p, u64]),
        "rl_sim_time_us": (u64, [p]),
        "rl_sim_set_encoder": (None, [p, u8, i32]),
        "rl_sim_add_encoder": (None, [p, u8, i32]),
        "rl_sim_get_outputs": (None, [p, ctypes.POINTER(_RawOutputs)]),
        "rl_sim_eeprom_size": (u32, []),
        "rl_sim_eeprom_read": (ctypes.c_int, [p, u32, ctypes.c_void_p, u32]),
        "rl_sim_eeprom_write": (ctypes.c_int, [p, u32, buf, u32]),
        "rl_sim_eeprom_erase": (None, [p]),
        "rl_sim_eeprom_fail_writes": (None, [p, ctypes.c_int]),
    }
    for name, (restype, argtypes) in signatures.items():
        fn = getattr(lib, name)
        fn.restype = restype
        fn.argtypes = argtypes


@functools.cache
def library() -> ctypes.CDLL:
    """The loaded library, built first if needed (once per process)."""
    path = build()
    lib = ctypes.CDLL(str(path))
    _declare(lib)
    if lib.rl_sim_api_version() != API_VERSION:
        raise SimError(f"{path}: API version {lib.rl_sim_api_version()}, this wrapper speaks {API_VERSION}")
    if lib.rl_sim_outputs_size() != ctypes.sizeof(_RawOutputs):
        raise SimError(
            f"{path}: rl_sim_outputs is {lib.rl_sim_outputs_size()} bytes, "
            f"the wrapper's {ctypes.sizeof(_RawOutputs)}: update _RawOutputs"
        )
    return lib


def profiles() -> dict[str, str]:
    """Profile name -> firmware example name, as the library knows them."""
    lib = library()
    out = {}
    for i in range(lib.rl_sim_profile_count()):
        out[lib.rl_sim_profile_name(i).decode()] = lib.rl_sim_profile_example(i).decode()
    return out


class NativeSim:
    """One simulated robot running the firmware core. Booted on construction."""

    EEPROM_SIZE = 1024

    def __init__(self, profile: str | int = "diffdrive-tb6612", seed: int = 1, *, poll_interval_us: int = 1000) -> None:
        """`profile`: a profile name ("picar"), an example name ("AckermannPiCar") or an index."""
        self._lib = library()
        handle = self._lib.rl_sim_create(str(profile).encode(), seed & 0xFFFFFFFF)
        if not handle:
            raise SimError(f"unknown profile {profile!r}: choose one of {', '.join(profiles())}")
        self._h: int | None = handle
        self.profile = str(profile)
        self.poll_interval_us = poll_interval_us

    # -- lifetime ---------------------------------------------------------------------------------
    def close(self) -> None:
        if self._h is not None:
            self._lib.rl_sim_destroy(self._h)
            self._h = None

    def __enter__(self) -> NativeSim:
        return self

    def __exit__(self, t: type[BaseException] | None, e: BaseException | None, tb: TracebackType | None) -> None:
        self.close()

    def __del__(self) -> None:
        self.close()

    @property
    def _handle(self) -> int:
        if self._h is None:
            raise SimError("the simulator was closed")
        return self._h

    # -- clock and bytes --------------------------------------------------------------------------
    @property
    def poll_interval_us(self) -> int:
        return self._poll_interval_us

    @poll_interval_us.setter
    def poll_interval_us(self, us: int) -> None:
        self._poll_interval_us = max(1, int(us))
        self._lib.rl_sim_set_poll_interval_us(self._handle, self._poll_interval_us)

    def set_boot_micros(self, us: int) -> None:
        """micros() at the next boot (reset()): to exercise the 32-bit wrap."""
        self._lib.rl_sim_set_boot_micros(self._handle, us & 0xFFFFFFFF)

    @property
    def time_us(self) -> int:
        return int(self._lib.rl_sim_time_us(self._handle))

    def feed(self, data: bytes) -> None:
        """Bytes from the host; handled at the next advance_us()."""
        if data:
            self._lib.rl_sim_feed_host_bytes(self._handle, bytes(data), len(data))

    def read(self) -> bytes:
        """Everything the firmware has written since the last read."""
        n = self._lib.rl_sim_mcu_bytes_available(self._handle)
        if n == 0:
            return b""
        buf = ctypes.create_string_buffer(n)
        got = self._lib.rl_sim_read_mcu_bytes(self._handle, buf, n)
        return buf.raw[:got]

    def advance_us(self, us: int = 0) -> None:
        """Handles the bytes fed so far, then runs `us` microseconds of simulated time."""
        if us < 0:
            raise ValueError("time only goes forward")
        self._lib.rl_sim_advance_us(self._handle, us)

    def advance_ms(self, ms: float) -> None:
        self.advance_us(round(ms * 1000))

    def reset(self) -> None:
        """Power cycle: a new boot (new boot_id, IDENTITY), EEPROM kept, encoders and bytes lost."""
        self._lib.rl_sim_reset(self._handle)

    # -- encoders and outputs ---------------------------------------------------------------------
    def set_encoder(self, wheel: int, count: int) -> None:
        """Sets the raw hardware counter (before the config's encoder_invert)."""
        self._lib.rl_sim_set_encoder(self._handle, wheel, _i32(count))

    def add_encoder(self, wheel: int, delta: int) -> None:
        self._lib.rl_sim_add_encoder(self._handle, wheel, _i32(delta))

    def outputs(self) -> Outputs:
        raw = _RawOutputs()
        self._lib.rl_sim_get_outputs(self._handle, ctypes.byref(raw))
        return Outputs._from_raw(raw)

    # -- EEPROM ------------------------------------------------------------------------------------
    def eeprom_read(self, address: int = 0, length: int = EEPROM_SIZE) -> bytes:
        buf = ctypes.create_string_buffer(max(length, 1))
        if not self._lib.rl_sim_eeprom_read(self._handle, address, buf, length):
            raise IndexError(f"EEPROM {address}..{address + length} is outside 0..{self.EEPROM_SIZE}")
        return buf.raw[:length]

    def eeprom_write(self, address: int, data: bytes) -> None:
        """Pokes bytes straight into the EEPROM (corruption tests); the firmware is not told."""
        if not self._lib.rl_sim_eeprom_write(self._handle, address, bytes(data), len(data)):
            raise IndexError(f"EEPROM {address}..{address + len(data)} is outside 0..{self.EEPROM_SIZE}")

    def eeprom_erase(self) -> None:
        self._lib.rl_sim_eeprom_erase(self._handle)

    def eeprom_fail_writes(self, fail: bool = True) -> None:
        self._lib.rl_sim_eeprom_fail_writes(self._handle, int(fail))


def _i32(x: int) -> int:
    x &= 0xFFFFFFFF
    return x - (1 << 32) if x & 0x80000000 else x


class HostLink(Link):
    """The shared host end (tests.support.hostlink) on the native core: frames are queued for the
    firmware and handled at the next run(); each received frame is stamped with the core's time."""

    def __init__(self, sim: NativeSim, first_seq: int = 0) -> None:
        super().__init__(sim.feed, sim.read, lambda: sim.time_us, first_seq)
        self.sim = sim

    def run(self, us: int = 0) -> list[Received]:
        """Advances the simulation and returns the frames the firmware sent meanwhile."""
        self.sim.advance_us(us)
        return self.receive()
