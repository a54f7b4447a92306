# DO NOT EDIT: generated from protocol/robots/*.toml and protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""Reference robot profiles by name: firmware defaults, kinematics, feedback mode, footprint and
sensor mounts (from protocol/robots/*.toml)."""

from __future__ import annotations

from dataclasses import dataclass

from protocol.generated.enums import Board, Capability, FeedbackMode, LightsMode, SafeState
from protocol.generated.messages import SetConfig, SetPid
from protocol.sensors import Mount, RobotSensors


@dataclass(frozen=True, slots=True)
class WiredPart:
    """A DC motor driver channel or an encoder, and the Arduino pins it is wired to."""

    kind: str
    """The motor's driver (TB6612, L298N, BTS7960) or "encoder"."""
    pins: tuple[tuple[str, int], ...]
    """(role, Arduino pin): pwm, in1, in2, standby / rpwm, lpwm, r_en, l_en / a, b."""

    def pin(self, role: str) -> int:
        return dict(self.pins)[role]


@dataclass(frozen=True, slots=True)
class Wiring:
    """Which Arduino pin serves which part (a robot file's pins: docs/robot-file.md)."""

    motors: tuple[WiredPart, ...]
    """DC motor driver channels, in wheel-channel order (none behind an ESC)."""
    encoders: tuple[WiredPart, ...]
    """Quadrature encoders, in wheel-channel order."""
    esc_pin: int | None
    """ESC signal."""
    servo_pin: int | None
    """Steering servo signal."""
    led_pins: tuple[int, ...]
    """One per Lights bit, in bit order (none without turn signals)."""
    entropy_pin: int
    """Analog pin left open: its noise seeds the boot_id."""


@dataclass(frozen=True, slots=True)
class RobotProfile:
    """One reference robot. `config` and `pid` are the firmware example's defaults."""

    name: str
    """Profile name (emulator and SDK)."""
    example: str
    """Firmware example (sketch folder) with these defaults."""
    doc: str
    """What the robot is."""
    board: Board
    """Board the example targets."""
    capabilities: Capability
    """Capabilities the example reports."""
    kinematics: str
    """"diff" or "ackermann"."""
    feedback_mode: FeedbackMode
    """Feedback mode the robot is used with."""
    lights_mode: LightsMode
    """The turn signals' mode at power-up and at each new session."""
    track_m: float
    """Distance between the left and right wheels."""
    wheelbase_m: float
    """Distance between the axles (Ackermann; 0 for diff-drive)."""
    wheel_diameter_m: float
    """Driven wheel diameter."""
    encoder_cpr: int
    """Encoder counts per wheel revolution."""
    config: SetConfig
    """Default configuration."""
    pid: SetPid
    """Default PID gains (all wheels)."""
    wiring: Wiring
    """Which Arduino pin serves which part."""


PROFILES: dict[str, RobotProfile] = {
    "diffdrive-bts7960": RobotProfile(
        name="diffdrive-bts7960",
        example="DiffDriveBTS7960",
        doc='3D-printed SLAM robot: Mega 2560, two BTS7960 drivers (RPWM/LPWM), 19.2:1 gearmotors with 64 CPR encoders, lockstep command/feedback.',
        board=Board.MEGA2560,
        capabilities=Capability.DIFF_DRIVE | Capability.ENCODERS | Capability.EEPROM | Capability.LOCKSTEP,
        kinematics="diff",
        feedback_mode=FeedbackMode.LOCKSTEP,
        lights_mode=LightsMode.AUTO,
        track_m=0.25,
        wheelbase_m=0.0,
        wheel_diameter_m=0.09,
        encoder_cpr=1216,
        config=SetConfig(watchdog_ms=250, safe_state=SafeState.RAMP_DOWN, accel_limit_mm_s2=1500, decel_limit_mm_s2=3000, max_wheel_speed_mm_s=1000, max_effort_permille=1000, encoder_cpr=1216, encoder_invert=0, motor_invert=0, wheel_diameter_um=90000, steering_center_cdeg=9000, steering_min_cdeg=9000, steering_max_cdeg=9000, steering_step_cdeg=0, servo_min_us=500, servo_max_us=2500, esc_min_us=1000, esc_neutral_us=1500, esc_max_us=2000, esc_arm_ms=0, feedback_hz=100),
        pid=SetPid(wheel=255, kp=0.6, ki=4.0, kd=0.0, kf=0.62, ks=62.0),
        wiring=Wiring(
            motors=(WiredPart("BTS7960", (("rpwm", 2), ("lpwm", 3), ("r_en", 22), ("l_en", 23),)), WiredPart("BTS7960", (("rpwm", 6), ("lpwm", 7), ("r_en", 24), ("l_en", 25),)),),
            encoders=(WiredPart("encoder", (("a", 62), ("b", 63),)), WiredPart("encoder", (("a", 64), ("b", 65),)),),
            esc_pin=None,
            servo_pin=None,
            led_pins=(),
            entropy_pin=54,
        ),
    ),
    "diffdrive-tb6612": RobotProfile(
        name="diffdrive-tb6612",
        example="DiffDriveTB6612",
        doc='ros_arduino_bridge-style differential-drive car: Mega 2560, TB6612 (or L298N), two quadrature encoders, four turn-signal LEDs, stream feedback.',
        board=Board.MEGA2560,
        capabilities=Capability.DIFF_DRIVE | Capability.ENCODERS | Capability.EEPROM | Capability.TURN_SIGNALS | Capability.LOCKSTEP,
        kinematics="diff",
        feedback_mode=FeedbackMode.STREAM,
        lights_mode=LightsMode.AUTO,
        track_m=0.2,
        wheelbase_m=0.0,
        wheel_diameter_m=0.064,
        encoder_cpr=1560,
        config=SetConfig(watchdog_ms=250, safe_state=SafeState.BRAKE, accel_limit_mm_s2=1000, decel_limit_mm_s2=2000, max_wheel_speed_mm_s=600, max_effort_permille=1000, encoder_cpr=1560, encoder_invert=2, motor_invert=2, wheel_diameter_um=64000, steering_center_cdeg=9000, steering_min_cdeg=9000, steering_max_cdeg=9000, steering_step_cdeg=0, servo_min_us=500, servo_max_us=2500, esc_min_us=1000, esc_neutral_us=1500, esc_max_us=2000, esc_arm_ms=0, feedback_hz=50),
        pid=SetPid(wheel=255, kp=1.0, ki=6.0, kd=0.0, kf=1.25, ks=70.0),
        wiring=Wiring(
            motors=(WiredPart("TB6612", (("pwm", 6), ("in1", 22), ("in2", 23), ("standby", 26),)), WiredPart("TB6612", (("pwm", 7), ("in1", 24), ("in2", 25), ("standby", 26),)),),
            encoders=(WiredPart("encoder", (("a", 2), ("b", 3),)), WiredPart("encoder", (("a", 18), ("b", 19),)),),
            esc_pin=None,
            servo_pin=None,
            led_pins=(30, 31, 32, 33,),
            entropy_pin=54,
        ),
    ),
    "picar": RobotProfile(
        name="picar",
        example="AckermannPiCar",
        doc='Ackermann PiCar: Uno, brushless drive motor behind an ESC (calibrated at boot), one motor encoder, steering servo 65..125 degrees in 15 degree steps, stream feedback.',
        board=Board.UNO,
        capabilities=Capability.ACKERMANN | Capability.ENCODERS | Capability.STEERING_SERVO | Capability.ESC | Capability.EEPROM,
        kinematics="ackermann",
        feedback_mode=FeedbackMode.STREAM,
        lights_mode=LightsMode.AUTO,
        track_m=0.16,
        wheelbase_m=0.26,
        wheel_diameter_m=0.065,
        encoder_cpr=720,
        config=SetConfig(watchdog_ms=250, safe_state=SafeState.BRAKE, accel_limit_mm_s2=2000, decel_limit_mm_s2=4000, max_wheel_speed_mm_s=2000, max_effort_permille=600, encoder_cpr=720, encoder_invert=0, motor_invert=0, wheel_diameter_um=65000, steering_center_cdeg=9000, steering_min_cdeg=6500, steering_max_cdeg=12500, steering_step_cdeg=1500, servo_min_us=500, servo_max_us=2500, esc_min_us=1000, esc_neutral_us=1500, esc_max_us=2000, esc_arm_ms=3000, feedback_hz=50),
        pid=SetPid(wheel=255, kp=0.3, ki=1.5, kd=0.0, kf=0.33, ks=85.0),
        wiring=Wiring(
            motors=(),
            encoders=(WiredPart("encoder", (("a", 2), ("b", 3),)),),
            esc_pin=9,
            servo_pin=10,
            led_pins=(),
            entropy_pin=14,
        ),
    ),
}
"""Reference robots by profile name."""

ROBOT_SENSORS: dict[str, RobotSensors] = {
    "diffdrive-bts7960": RobotSensors(
        profile="diffdrive-bts7960",
        footprint_radius_m=0.17,
        footprint_x_m=0.0,
        mounts=(
            Mount(device="rplidar-a1", name="lidar", x_m=0.0, y_m=0.0, z_m=0.22, yaw_deg=0.0),
        ),
    ),
    "diffdrive-tb6612": RobotSensors(
        profile="diffdrive-tb6612",
        footprint_radius_m=0.12,
        footprint_x_m=0.03,
        mounts=(
            Mount(device="jy901", name="imu", x_m=0.0, y_m=0.0, z_m=0.05, yaw_deg=0.0),
            Mount(device="pi-camera-v2", name="camera", x_m=0.1, y_m=0.0, z_m=0.14, yaw_deg=0.0),
        ),
    ),
    "picar": RobotSensors(
        profile="picar",
        footprint_radius_m=0.19,
        footprint_x_m=0.13,
        mounts=(
            Mount(device="ydlidar-f4", name="lidar", x_m=0.18, y_m=0.0, z_m=0.16, yaw_deg=0.0),
            Mount(device="pi-camera-v2", name="camera", x_m=0.3, y_m=0.0, z_m=0.12, yaw_deg=0.0),
        ),
    ),
}
"""Each reference robot's footprint (as a disc) and sensor mounts, by profile name."""
