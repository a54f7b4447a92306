"""Ground truth: everything a test may want to assert on, as frozen snapshots.

`Emulator.truth` builds one `Truth` per call. Plant quantities are what physically happens
(pose, wheel speeds, motor voltages and currents, encoder edges); firmware quantities are what the
emulated MCU believes (session state, targets, efforts, counters); `faults` logs every injected
fault with the virtual time it took effect.
"""

from __future__ import annotations

from dataclasses import dataclass

from emulator.firmware.config import Gains
from emulator.firmware.statemachine import SessionEvent, SessionState
from emulator.plant.esc import EscState
from emulator.world.world import WorldTruth
from protocol.generated.enums import FailsafeReason, FeedbackMode, Status
from protocol.generated.hardware import MotorMode
from protocol.generated.messages import LinkStats, SetConfig


@dataclass(frozen=True, slots=True)
class FaultRecord:
    time_us: int
    """Virtual time the fault took effect."""
    kind: str
    """bitflip, drop, insert, noise, cut, restore, reset, dtr_reset, bootloader_garbage, brownout,
    stall, unstall, encoder_disconnect, encoder_reconnect, eeprom_fail, eeprom_ok, traction,
    bitflip_rate, drop_rate, insert_rate (a rate was set), stand, rx_overrun (an effect: host bytes lost
    in the MCU's full receive buffer), sensor_fail (an emulated sensor's update raised: it is dead)."""
    detail: str


@dataclass(frozen=True, slots=True)
class FirmwareTruth:
    state: SessionState
    boot_id: int
    boot_count: int
    micros: int
    tick: int
    watchdog_ms: int
    """Granted watchdog period of the session (the config default in IDLE)."""
    feedback_mode: FeedbackMode
    feedback_hz: int
    failsafe_reason: FailsafeReason
    status: Status
    config: SetConfig
    gains: tuple[Gains, ...]
    config_defaults: bool
    targets_mm_s: tuple[float, ...]
    ramped_mm_s: tuple[float, ...]
    measured_mm_s: tuple[int, ...]
    efforts_permille: tuple[int, ...]
    integrals: tuple[float, ...]
    encoder_counts: tuple[int, ...]
    encoder_fault: tuple[bool, ...]
    ack_seq: int
    ack_tick: int
    steering_cdeg: int
    esc_hold: bool
    """Still inside the ESC arming window after boot (drive held at neutral)."""
    last_valid_frame_us: int
    link: LinkStats
    """The link counters: LINK_STATS as the firmware would answer GET_LINK_STATS now (req_seq 0)."""
    transitions: tuple[tuple[SessionState, SessionEvent, SessionState], ...]
    """Session transitions that fired since boot (VALID_FRAME/SETPOINT self-loops left out)."""


@dataclass(frozen=True, slots=True)
class WheelTruth:
    rim_speed_mm_s: float
    """Wheel angular speed times radius (what an ideal encoder measures)."""
    ground_speed_mm_s: float
    """Speed of the ground under the tyre (differs from the rim speed when the tyre slips)."""
    angle_rad: float
    revolutions: float
    duty: float
    """Bridge duty commanded (-1..1; for the ESC robot, the ESC's throttle)."""
    mode: MotorMode
    voltage_v: float
    current_a: float
    torque_nm: float
    encoder_edges: int
    """Edges the encoder has produced since power-up (robot-forward positive before mirroring)."""
    encoder_connected: bool
    stalled: bool
    slipping: bool


@dataclass(frozen=True, slots=True)
class PlantTruth:
    x_m: float
    y_m: float
    theta_rad: float
    """Heading, unwrapped (counter-clockwise positive)."""
    speed_m_s: float
    yaw_rate_rad_s: float
    distance_m: float
    wheels: tuple[WheelTruth, ...]
    steering_rad: float
    """Actual front-wheel angle (0 without steering)."""
    servo_deg: float | None
    servo_pulse_us: int | None
    esc_state: EscState | None
    esc_pulse_us: int | None
    esc_neutral_us: int | None
    """Neutral the ESC learned during its calibration."""
    leds: dict[str, bool]
    led_toggles: tuple[int, ...]
    traction_mu: float
    on_stand: bool = False
    """Lifted onto a stand: the wheels spin in the air and the body does not move."""


@dataclass(frozen=True, slots=True)
class LineTruth:
    bytes_sent: int
    bytes_delivered: int
    bits_flipped: int
    bytes_dropped: int
    bytes_inserted: int
    bytes_lost_cut: int
    noise_bytes: int
    cut: bool
    in_flight: int


@dataclass(frozen=True, slots=True)
class McuTruth:
    phase: str
    """"running", "bootloader" or "reset" (held in reset during a brown-out)."""
    resets: int
    """Resets since the emulator started (any cause)."""
    boot_ids: tuple[int, ...]
    """boot_id of every boot so far, oldest first."""
    bytes_lost_not_running: int
    """Host bytes that reached the MCU while it was in reset or in the bootloader."""
    rx_overrun_bytes: int
    """Host bytes lost in a full receive buffer while the loop was stalled (the firmware cannot
    see these: LINK_STATS.rx_overruns stays 0, as on an Arduino)."""
    ticks_skipped: int
    """Control ticks skipped because the loop was stalled (EEPROM writes)."""
    eeprom_failing: bool


@dataclass(frozen=True, slots=True)
class Truth:
    time_us: int
    profile: str
    seed: int
    mcu: McuTruth
    firmware: FirmwareTruth | None
    """None while the MCU is in reset or in its bootloader."""
    plant: PlantTruth
    host_to_mcu: LineTruth
    mcu_to_host: LineTruth
    faults: tuple[FaultRecord, ...]
    world: WorldTruth | None = None
    """The robot in its world (pose, target, collisions) when one is attached, else None."""

    @property
    def status(self) -> Status:
        return self.firmware.status if self.firmware is not None else Status(0)

    def fault_kinds(self) -> list[str]:
        return [f.kind for f in self.faults]
