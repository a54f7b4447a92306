"""`Robot.connect(url, robot=FILE)`: the robot file against the board it connects to.

The rule (docs/robot-file.md, "Connecting with a robot file"):

- compared: what identifies the build, fixed when the firmware was built from the file: the
  board (a real one: the emulator and the host build stand in for any), the drive kind and its
  wheel count, the capabilities the file derives (encoders, lights, lockstep), the robot's name,
  the firmware defaults the hardware fixes (wheel diameter, encoder counts, inverts, steering
  range, servo and ESC pulses), and the turn signals' power-up mode (`[lights] mode`, read with
  GET_LIGHTS: a new session starts in it). A difference means another robot or another build: an error
  naming both sides, or with `allow_mismatch=True` a warning kept in `robot.mismatches`;
- applied: the file's limits, feedback rate and PID gains (each wheel its own), and its measured
  calibration where the board still has the nominal value, sent with set_config/set_pid when they
  differ, because the file is what the robot runs with (tuning it means editing the file, not
  re-flashing). Changed gains are said in one line (`gains_notice`): the board's own, e.g. saved
  by `roverlink tune`, are not replaced unseen.
"""

from __future__ import annotations

import dataclasses
import logging
import struct
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

from host_sdk import checks
from host_sdk.errors import ArgumentError, RoverLinkError
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.lights import LightsStatus
from host_sdk.profiles import get_profile, kinematics_for, profile_for_example
from host_sdk.robot_description import RobotDescription
from host_sdk.session import PidGains, RobotConfig, RobotIdentity
from host_sdk.transport import Transport
from protocol.generated.enums import Board, Capability
from protocol.generated.profiles import PROFILES
from protocol.robotfile import Calibration

MISMATCH_LOGGER = "host_sdk.robot_file"
"""Where the differences allowed with allow_mismatch are logged (a program that reports
`robot.mismatches` itself may keep this logger quiet)."""
_log = logging.getLogger(MISMATCH_LOGGER)


class Configurable(Protocol):
    """What of a Robot the check reads and sets (Robot is one)."""

    @property
    def identity(self) -> RobotIdentity: ...
    @property
    def config(self) -> RobotConfig: ...
    def lights(self) -> LightsStatus: ...
    def set_config(self, **changes: Any) -> RobotConfig: ...
    def pid(self, wheel: int = 0) -> PidGains: ...
    @property
    def set_pid(self) -> Callable[..., PidGains]: ...  # Robot.set_pid: gains by name, and wheel


# CONFIG fields the file's hardware fixes: (field, the file's key, scale to the file's unit, unit).
_BUILD = (
    ("wheel_diameter_um", "geometry.wheel_diameter_m", 1e-6, "m"),
    ("encoder_cpr", "encoders.counts_per_rev", 1.0, "counts/rev"),
    ("encoder_invert", "encoders.invert", 0.0, ""),
    ("motor_invert", "drive.motor_invert", 0.0, ""),
)
_STEERED = (
    ("steering_center_cdeg", "steering.center_deg", 0.01, "deg"),
    ("steering_min_cdeg", "steering.min_deg", 0.01, "deg"),
    ("steering_max_cdeg", "steering.max_deg", 0.01, "deg"),
    ("steering_step_cdeg", "steering.step_deg", 0.01, "deg"),
    ("servo_min_us", "steering.min_pulse_s", 1e-6, "s"),
    ("servo_max_us", "steering.max_pulse_s", 1e-6, "s"),
    ("esc_min_us", "esc.min_pulse_s", 1e-6, "s"),
    ("esc_neutral_us", "esc.neutral_pulse_s", 1e-6, "s"),
    ("esc_max_us", "esc.max_pulse_s", 1e-6, "s"),
    ("esc_arm_ms", "esc.arm_s", 1e-3, "s"),
)
_CALIBRATED = {
    "wheel_diameter_um": "calibration.wheel_diameter_m",
    "encoder_cpr": "calibration.counts_per_rev",
    "steering_center_cdeg": "steering.center_deg + calibration.steering_trim_deg",
}
APPLIED = (
    "watchdog_ms",
    "safe_state",
    "accel_limit_mm_s2",
    "decel_limit_mm_s2",
    "max_wheel_speed_mm_s",
    "max_effort_permille",
    "feedback_hz",
)
"""CONFIG fields set from the file at connect (limits and feedback), besides the PID gains."""
_FLAGS = (  # capability, the file's key, how the file says it has it not / has it
    (Capability.ENCODERS, "encoders.pins", ("none", "given")),
    (Capability.TURN_SIGNALS, "[lights]", ("none", "given")),
    (Capability.LOCKSTEP, "feedback.lockstep", ("false", "true")),
)
_NAME_LEN = 24  # IDENTITY.robot_name is char[..24]


@dataclass(frozen=True)
class Mismatch:
    """One way the board differs from the robot file: the file's key and value, the board's."""

    path: str
    key: str
    file_value: str
    url: str
    field: str
    board_value: str

    def __str__(self) -> str:
        board = f"the board on {self.url} has {self.field} = {self.board_value}"
        return f"{self.path}: {self.key} = {self.file_value} but {board}"


class RobotMismatchError(RoverLinkError, ValueError):
    """The board is not the robot the file describes. `mismatches` lists each difference (the
    file's key and value, the board's field and value); the message names them all and the fix."""

    def __init__(self, mismatches: tuple[Mismatch, ...], path: str) -> None:
        self.mismatches = mismatches
        fix = f"flash the firmware built from this file (roverlink firmware build --robot {path}) or fix the file"
        if len(mismatches) == 1:
            super().__init__(f"{mismatches[0]}: {fix}")
        else:
            lines = "\n".join(f"  {m}" for m in mismatches)
            super().__init__(f"{path} does not describe the board ({len(mismatches)} differences):\n{lines}\n{fix}")


class RobotFileCheck:
    """One connect's robot file: its kinematics, the comparison, what to apply."""

    def __init__(self, description: RobotDescription, allow_mismatch: bool) -> None:
        self.description = description
        self.allow_mismatch = allow_mismatch
        self.mismatches: tuple[Mismatch, ...] = ()
        self.gains_notice: str | None = None
        """Set when the connect changed the board's gains to the file's (one line saying how)."""

    def compare(self, identity: RobotIdentity, config: RobotConfig | None, url: str) -> None:
        """Compare the build; RobotMismatchError lists every difference (a warning when allowed)."""
        assert config is not None  # read in the handshake
        self.mismatches = tuple(compare(self.description, identity, config, url))
        if not self.mismatches:
            return
        error = RobotMismatchError(self.mismatches, self.description.path)
        if not self.allow_mismatch:
            raise error
        _log.warning("allow_mismatch: %s", error)

    def compare_lights(self, robot: Configurable, url: str) -> None:
        """The power-up mode of the turn signals, which the new session has just brought back
        (RobotMismatchError, or with allow_mismatch a warning, when it is not the file's)."""
        desc = self.description
        if not robot.identity.capabilities & Capability.TURN_SIGNALS or not desc.wiring.led_pins:
            return  # no lights on one side: the capabilities' comparison said so already
        mode = robot.lights().mode
        want = desc.lights_mode()
        if mode is want:
            return
        row = Mismatch(desc.path, "lights.mode", want.name.lower(), url, "power-up lights mode", mode.name)
        self.mismatches = (*self.mismatches, row)
        error = RobotMismatchError(self.mismatches, desc.path)
        if not self.allow_mismatch:
            raise error
        _log.warning("allow_mismatch: %s", error)

    def apply(self, robot: Configurable) -> None:
        """Send the file's limits, feedback rate, calibration and PID gains where the board's differ."""
        changes = changes_for(self.description, robot.config)
        if changes:
            robot.set_config(**changes)
        wheels = 2 if robot.identity.capabilities & Capability.DIFF_DRIVE else 1
        changed = []
        for w in range(wheels):
            board = robot.pid(w)
            want = PidGains(*self.description.pid.of_wheel(w))
            if _f32(dataclasses.astuple(board)) != _f32(dataclasses.astuple(want)):
                robot.set_pid(**dataclasses.asdict(want), wheel=w)
                changed.append((w, board, want))
        if changed:
            # The board's own gains (EEPROM, e.g. from `roverlink tune --save`) are replaced in RAM:
            # said once, so gains that differ from the file are never undone unseen.
            self.gains_notice = gains_notice(self.description.path, changed)
            _log.warning("%s", self.gains_notice)


def gains_notice(path: str, changed: list[tuple[int, PidGains, PidGains]]) -> str:
    """One line: which wheels' gains the file changed on the board, from what to what."""
    parts = []
    for wheel, board, want in changed:
        diffs = [
            f"{f.name} {getattr(board, f.name):g} -> {getattr(want, f.name):g}"
            for f in dataclasses.fields(PidGains)
            if _f32((getattr(board, f.name),)) != _f32((getattr(want, f.name),))
        ]
        parts.append(f"wheel {wheel} " + ", ".join(diffs))
    return f"{path} [pid] set on the board (its stored gains differ): " + "; ".join(parts)


def prepare(robot: object, profile: object, kinematics: object, allow_mismatch: object) -> RobotFileCheck | None:
    """`connect`'s robot= and allow_mismatch=, checked: None without a file; RobotFileError lists a
    bad file's problems."""
    mismatch_ok = checks.flag("allow_mismatch", allow_mismatch)
    if robot is None:
        return None
    allowed = "a robot file's path (str or Path) or a RobotDescription, without profile= or kinematics="
    checks.instance("robot", robot, (str, Path, RobotDescription), allowed)
    if profile is not None or kinematics is not None:
        raise ArgumentError("robot", robot, allowed)
    desc = robot if isinstance(robot, RobotDescription) else RobotDescription.load(robot)  # type: ignore[arg-type]
    return RobotFileCheck(desc, mismatch_ok)


def chosen_kinematics(
    user: DiffDrive | Ackermann | None,
    profile: str | None,
    transport: Transport,
    identity: RobotIdentity,
    config: RobotConfig,
) -> DiffDrive | Ackermann | None:
    """The kinematics a connect uses: the caller's (or its robot file's), an emu://?robot=PATH
    file's, the profile's (named, the emulator's, or the firmware example's), else None."""
    if user is not None:
        return user
    if profile is None and transport.robot_file is not None:
        return RobotDescription.load(transport.robot_file).kinematics()  # emu://?robot=PATH
    name = profile or transport.profile
    prof = get_profile(name, argument="profile") if name is not None else profile_for_example(identity.robot_name)
    return kinematics_for(prof, config) if prof is not None else None


def _f32(values: tuple[float, ...]) -> bytes:
    return struct.pack(f"<{len(values)}f", *values)  # gains travel as float32


def _names(robot_file_name: str) -> set[str]:
    """Names a board running this file's firmware reports: its own, or a reference example's."""
    names = {robot_file_name, robot_file_name[:_NAME_LEN]}
    profile = PROFILES.get(robot_file_name)
    if profile is not None:
        names.add(profile.example)
    return names


def _drive(caps: Capability) -> str:
    if caps & Capability.DIFF_DRIVE:
        return "DIFF_DRIVE (2 wheels)"
    return "ACKERMANN (1 wheel)" if caps & Capability.ACKERMANN else "neither DIFF_DRIVE nor ACKERMANN"


def _identity(desc: RobotDescription, identity: RobotIdentity) -> list[tuple[str, str, str, str]]:
    out: list[tuple[str, str, str, str]] = []
    if identity.board in (Board.UNO, Board.MEGA2560) and identity.board is not desc.board_enum():
        out.append(("board", f'"{desc.board}"', "board", identity.board.name))
    caps, mine = identity.capabilities, desc.capabilities()
    kind = Capability.DIFF_DRIVE if desc.drive.kind == "differential" else Capability.ACKERMANN
    if not caps & kind:
        wheels = f"{desc.drive.channels} wheel{'s' if desc.drive.channels > 1 else ''}"
        out.append(("drive.kind", f'"{desc.drive.kind}" ({wheels})', "capabilities", _drive(caps)))
    for flag, key, says in _FLAGS:
        if bool(caps & flag) != bool(mine & flag):
            out.append((key, says[bool(mine & flag)], "capabilities", f"{'' if caps & flag else 'no '}{flag.name}"))
    if identity.robot_name and identity.robot_name not in _names(desc.name):
        out.append(("name", f'"{desc.name}"', "robot_name", f'"{identity.robot_name}"'))
    return out


def _file_text(value: int, scale: float, unit: str, channels: int) -> str:
    """A CONFIG value as the file writes it: in its unit, per-wheel flags as a list."""
    if scale == 0.0:
        return "[" + ", ".join("true" if value >> i & 1 else "false" for i in range(channels)) + "]"
    return f"{value * scale:g} {unit}" if scale != 1.0 else str(value)


def _board_text(value: int, scale: float, unit: str) -> str:
    """A CONFIG value as the board has it, with the file's unit beside it."""
    if scale == 0.0:
        return f"{value:#04b} (bit i: wheel i)"
    return f"{value} ({value * scale:g} {unit})" if scale != 1.0 else str(value)


def compare(desc: RobotDescription, identity: RobotIdentity, config: RobotConfig, url: str) -> list[Mismatch]:
    """Every difference between the file and the board's IDENTITY and CONFIG (see the module doc)."""
    rows = _identity(desc, identity)
    want, nominal = desc.config(), _nominal(desc)
    fields = _BUILD + (_STEERED if desc.steering is not None else ())
    for field, key, scale, unit in fields:
        board, mine, plain = getattr(config, field), getattr(want, field), getattr(nominal, field)
        if board in (mine, plain):
            continue  # the nominal value is fine: connect applies the calibrated one
        name = _CALIBRATED[field] if mine != plain and field in _CALIBRATED else key
        channels = desc.drive.channels
        rows.append((name, _file_text(mine, scale, unit, channels), field, _board_text(board, scale, unit)))
    return [Mismatch(desc.path, key, mine, url, field, board) for key, mine, field, board in rows]


def _nominal(desc: RobotDescription) -> RobotConfig:
    """The file's SET_CONFIG without its measured calibration (what its firmware was built with
    before it was calibrated)."""
    return dataclasses.replace(desc, calibration=Calibration()).config()


def changes_for(desc: RobotDescription, config: RobotConfig) -> dict[str, object]:
    """The CONFIG fields connect sets from the file: limits and feedback, and the calibrated
    values the board does not have yet."""
    want, nominal = desc.config(), _nominal(desc)
    out: dict[str, object] = {f: getattr(want, f) for f in APPLIED if getattr(want, f) != getattr(config, f)}
    for field in _CALIBRATED:
        mine = getattr(want, field)
        if field == "steering_center_cdeg" and desc.steering is None:
            continue
        if mine != getattr(nominal, field) and getattr(config, field) == getattr(nominal, field):
            out[field] = mine
    return out
