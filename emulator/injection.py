"""The fault-injection API, shared by the Python emulator (`emulator.Emulator`) and the
firmware-in-the-loop backends (`emulator.backends.simavr.PlantLoop`).

Line faults act on a `SerialLink` (emulator/line.py), plant faults on the `Plant`; resets and the
EEPROM are the backend's own (`reset_mcu`, `dtr_reset`, `brown_out`, `fail_eeprom`). A fault spec
(emulator/faults.py) is scheduled on the backend's `VirtualClock`. A backend that cannot model an
item lists it in `UNSUPPORTED_FAULTS` with the reason; `apply_faults` refuses such a spec.
"""

from __future__ import annotations

import enum
import functools
import math
from typing import ClassVar

from emulator.clock import PRIORITY_FAULT, VirtualClock
from emulator.errors import EmulatorValueError, FaultSpecError
from emulator.faults import FaultItem, FaultSpec, parse_faults
from emulator.line import SerialLink
from emulator.plant.plant import Plant
from emulator.profiles import EmulatorProfile
from emulator.truth import FaultRecord

MAX_FAULT_LOG = 100_000


def checked_board_options(
    profile: EmulatorProfile, latency_us: int, drift_ppm: float, bootloader_ms: int | None
) -> int:
    """Checks the board and line options every backend takes; returns the bootloader time in ms
    (the profile's when None)."""
    if not (isinstance(latency_us, int) and 0 <= latency_us <= 1_000_000):
        raise EmulatorValueError("latency_us", latency_us, "an integer in 0..1000000 us")
    if not (math.isfinite(drift_ppm) and abs(drift_ppm) <= 10_000):
        raise EmulatorValueError("drift_ppm", drift_ppm, "a number in -10000..10000 ppm")
    ms = profile.plant.timing.bootloader_ms if bootloader_ms is None else bootloader_ms
    if not (isinstance(ms, int) and 0 <= ms <= 60_000):
        raise EmulatorValueError("bootloader_ms", bootloader_ms, "an integer in 0..60000 ms")
    return ms


class ResetKind(enum.Enum):
    POWER_ON = "power_on"
    EXTERNAL = "reset"
    DTR = "dtr_reset"
    BROWN_OUT = "brownout"


class FaultInjection:
    """Mixin: the fault methods of docs/emulator.md, "Faults". The class using it provides `clock`,
    `link`, `plant`, `profile`, `faults`, `faults_dropped` and the reset and EEPROM methods."""

    UNSUPPORTED_FAULTS: ClassVar[dict[str, str]] = {}
    """Fault kinds this backend cannot model, each with the reason (for the error message)."""

    clock: VirtualClock
    link: SerialLink
    plant: Plant
    profile: EmulatorProfile
    faults: list[FaultRecord]
    faults_dropped: int

    # -- provided by the backend ---------------------------------------------------------------------
    def _begin_reset(self, kind: ResetKind, hold_us: int) -> None:
        """RAM and outputs lost, EEPROM kept; an external or DTR reset runs the bootloader, a
        brown-out holds the MCU in reset `hold_us` and the ESC loses its calibration."""
        raise NotImplementedError

    def fail_eeprom(self, failing: bool = True) -> None:
        raise NotImplementedError

    def _h2m_wake(self, time_us: int) -> None:
        """Bytes (noise) will reach the MCU at `time_us`: a backend that is woken by arrivals
        schedules itself; one that polls every step needs nothing."""

    # -- resets ------------------------------------------------------------------------------------------
    def reset_mcu(self) -> None:
        """Reset pin pulled (or the firmware's watchdog bit): bootloader, then a new boot."""
        self._log(self.clock.now_us, "reset", "external reset")
        self._begin_reset(ResetKind.EXTERNAL, 0)

    def dtr_reset(self) -> None:
        """What opening the port does to an Arduino: DTR pulses the reset pin."""
        self._log(self.clock.now_us, "dtr_reset", "DTR reset (port opened)")
        self._begin_reset(ResetKind.DTR, 0)

    def brown_out(self, duration_ms: float = 50.0) -> None:
        """Supply dip: the MCU is held in reset for `duration_ms`, the ESC loses its calibration
        (and, where the backend models it, an EEPROM write in progress is cut short)."""
        if not (math.isfinite(duration_ms) and 0 < duration_ms <= 60_000):
            raise EmulatorValueError("duration_ms", duration_ms, "a number of ms in (0, 60000]")
        self._log(self.clock.now_us, "brownout", f"{duration_ms} ms")
        self._begin_reset(ResetKind.BROWN_OUT, round(duration_ms * 1000))

    # -- the log ---------------------------------------------------------------------------------------
    def _log(self, time_us: int, kind: str, detail: str) -> None:
        if len(self.faults) < MAX_FAULT_LOG:
            self.faults.append(FaultRecord(time_us, kind, detail))
        else:
            self.faults_dropped += 1

    # -- the line ----------------------------------------------------------------------------------------
    def cut_link(self, direction: str = "both") -> None:
        """Cut the cable: bytes in flight and bytes sent from now on are lost."""
        for line in self.link.lines(direction):
            line.set_cut(True, self.clock.now_us)
        self._log(self.clock.now_us, "cut", direction)

    def restore_link(self, direction: str = "both") -> None:
        for line in self.link.lines(direction):
            line.set_cut(False, self.clock.now_us)
        self._log(self.clock.now_us, "restore", direction)

    def _set_rate(self, kind: str, rate: float, direction: str | None) -> None:
        if not (0.0 <= rate <= 1.0):
            raise EmulatorValueError(kind, rate, "a probability in 0..1")
        for line in self.link.lines(direction):
            setattr(line, kind, rate)
        self._log(self.clock.now_us, f"{kind}_rate", f"{direction or 'both'} {rate}")

    def set_bitflip_rate(self, rate: float, direction: str = "both") -> None:
        """Probability that each data bit flips."""
        self._set_rate("bitflip", rate, direction)

    def set_drop_rate(self, rate: float, direction: str = "both") -> None:
        """Probability that each byte is lost."""
        self._set_rate("drop", rate, direction)

    def set_insert_rate(self, rate: float, direction: str = "both") -> None:
        """Probability that a random byte follows each byte."""
        self._set_rate("insert", rate, direction)

    def noise_burst(self, duration_s: float, ber: float = 0.02, direction: str = "both") -> None:
        """Electrical noise from now for `duration_s`: bit errors and random bytes."""
        now = self.clock.now_us
        end = now + round(duration_s * 1e6)
        for line in self.link.lines(direction):
            wake = line.noise_burst(now, end, ber)
            if line is self.link.h2m:
                self._h2m_wake(wake)

    # -- the plant -----------------------------------------------------------------------------------------
    def _check_wheel(self, wheel: int) -> None:
        units = len(self.plant.units)
        if not (isinstance(wheel, int) and 0 <= wheel < units):
            raise EmulatorValueError("wheel", wheel, f"a wheel index in 0..{units - 1} for {self.profile.name}")

    def stall_wheel(self, wheel: int, stalled: bool = True) -> None:
        """Jam a wheel (it cannot turn; its motor draws stall current)."""
        self._check_wheel(wheel)
        self.plant.units[wheel].stalled = stalled
        self._log(self.clock.now_us, "stall" if stalled else "unstall", f"wheel {wheel}")

    def release_wheel(self, wheel: int) -> None:
        self.stall_wheel(wheel, False)

    def disconnect_encoder(self, wheel: int, disconnected: bool = True) -> None:
        """Pull an encoder's signal wire: its count freezes while the wheel keeps turning."""
        self._check_wheel(wheel)
        unit = self.plant.units[wheel]
        assert unit.encoder is not None
        if disconnected:
            unit.encoder.connected = False
        else:
            unit.encoder.reconnect(unit.angle_rad)
        kind = "encoder_disconnect" if disconnected else "encoder_reconnect"
        self._log(self.clock.now_us, kind, f"wheel {wheel}")

    def reconnect_encoder(self, wheel: int) -> None:
        self.disconnect_encoder(wheel, False)

    def set_traction(self, mu: float) -> None:
        """Tyre friction coefficient (math.inf: never slips)."""
        if not (mu >= 0 and not math.isnan(mu)):
            raise EmulatorValueError("mu", mu, "a friction coefficient >= 0 (or math.inf)")
        self.plant.vehicle.mu = mu
        self._log(self.clock.now_us, "traction", f"mu {mu}")

    # -- a spec -------------------------------------------------------------------------------------------
    def check_faults(self, spec: str | FaultSpec | None) -> FaultSpec:
        """Parse `spec` and refuse what this backend or robot cannot do (FaultSpecError naming the
        item and why)."""
        spec = parse_faults(spec) if isinstance(spec, str) or spec is None else spec
        for item in spec.items:
            reason = self.UNSUPPORTED_FAULTS.get(item.kind)
            if reason is not None:
                raise FaultSpecError(item.token, reason)
            if item.kind in ("stall", "encoder") and item.value is not None and item.value >= len(self.plant.units):
                raise FaultSpecError(
                    item.token, f"wheel must be 0..{len(self.plant.units) - 1} for {self.profile.name}"
                )
        return spec

    def apply_faults(self, spec: str | FaultSpec) -> None:
        """Apply a fault spec (see emulator.faults): standing items now, timed ones when due."""
        spec = self.check_faults(spec)
        for item in spec.items:
            if item.start_us is None:
                self._apply_item(item, undo=False)
                continue
            self.clock.call_at(item.start_us, functools.partial(self._apply_item, item, False), PRIORITY_FAULT)
            if item.end_us is not None and item.kind != "noise":
                self.clock.call_at(item.end_us, functools.partial(self._apply_item, item, True), PRIORITY_FAULT)

    def _apply_item(self, item: FaultItem, undo: bool) -> None:
        kind, value, direction = item.kind, item.value, item.direction
        if kind in ("bitflip", "drop", "insert"):
            self._set_rate(kind, 0.0 if undo else float(value or 0.0), direction)
        elif kind == "traction":
            self.set_traction(self.profile.plant.body.mu if undo else float(value if value is not None else 0.0))
        elif kind == "cut":
            (self.restore_link if undo else self.cut_link)(direction or "both")
        elif kind == "noise":
            assert item.end_us is not None and item.start_us is not None
            self.noise_burst((item.end_us - item.start_us) / 1e6, value or 0.02, direction or "both")
        elif kind == "reset":
            self.reset_mcu()
        elif kind == "dtr":
            self.dtr_reset()
        elif kind == "brownout":
            self.brown_out(value or 50.0)
        elif kind == "stall":
            self.stall_wheel(int(value or 0), not undo)
        elif kind == "encoder":
            self.disconnect_encoder(int(value or 0), not undo)
        elif kind == "eeprom":
            self.fail_eeprom(not undo)
