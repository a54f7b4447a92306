"""The plant loop: the emulator's plant around an MCU, on a virtual clock, behind the emulator's
serial line. The MCU is the simavr harness (simavr/robot.py), the rp2040js harness
(rp2040/robot.py) or, in the conformance tests, a native build of the firmware core: anything
with `step()` and `reset()`."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar, Protocol

from emulator.backends.pins import RELEASED, PinState
from emulator.clock import VirtualClock
from emulator.device import ResetKind
from emulator.errors import BackendError
from emulator.faults import FaultSpec
from emulator.injection import FaultInjection, checked_board_options
from emulator.line import SerialLink
from emulator.plant.plant import WHEEL_CHANNELS, Plant
from emulator.profiles import EmulatorProfile, get_profile
from emulator.rng import Streams
from emulator.truth import FaultRecord, LineTruth
from protocol.framing import Frame, FrameDecoder
from protocol.generated.enums import IdentityReason
from protocol.generated.messages import Identity

PHYSICS_US = 1000
BAUD = 115200


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
        "eeprom": "not available with the firmware backends: simavr programs every EEPROM cell the "
        "firmware writes (it has no failing-cell model), so a write cannot be made to fail, and the "
        "Pico keeps no configuration",
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
        self.pins = RELEASED
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
            self.pins = RELEASED
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
        self.pins = RELEASED
        bootloader = kind in (ResetKind.EXTERNAL, ResetKind.DTR)
        self.link.mcu_reset(now, bootloader=bootloader)
        if kind is ResetKind.BROWN_OUT:
            self.plant.power_cycle()
        if bootloader:
            self._restart_at = now + self.bootloader_ms * 1000
        else:
            self._restart_at = now + hold_us + self.profile.plant.timing.power_on_ms * 1000

    def fail_eeprom(self, failing: bool = True) -> None:
        raise BackendError(f"fail_eeprom: {self.UNSUPPORTED_FAULTS['eeprom']}")

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
