"""Every key of a robot file: its type, unit, allowed range, default and meaning.

One table drives the reader (types, ranges, unknown keys), the reference files' comments and the
key tables of docs/robot-file.md. Ranges of values the firmware receives come from the spec
(SET_CONFIG's limits), converted from the firmware's units (mm/s, cdeg, us) to the file's SI ones.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from protocol.generated.messages import SetConfig, SetPid

REQUIRED = object()
"""Default of a key the file must give."""
ABSENT = None
"""Default of an optional key whose absence means something (not wired, not measured)."""


@dataclass(frozen=True)
class Key:
    name: str
    type: str
    """str, int, float, bool, choice, pin (number or "A<n>"), bools (one per wheel channel),
    parts (a list of pin tables), points (a list of [x, y]), gain (a number, or a list of numbers
    one per wheel channel where the wheels' gains differ)."""
    unit: str
    doc: str
    default: object = REQUIRED
    lo: float | None = None
    hi: float | None = None
    choices: tuple[str, ...] = ()

    def allowed(self) -> str:
        """What the key accepts, in words (for error messages and the docs)."""
        if self.choices:
            return "one of " + ", ".join(self.choices)
        if self.type == "gain":
            return f"{self.lo:g}..{self.hi:g} {self.unit}, or a list of such numbers, one per wheel channel"
        if self.lo is not None and self.hi is not None:
            return f"{self.lo:g}..{self.hi:g}" + (f" {self.unit}" if self.unit else "")
        if self.lo is not None:
            return f">= {self.lo:g}" + (f" {self.unit}" if self.unit else "")
        return {
            "str": "a string",
            "int": "a whole number",
            "float": "a number",
            "bool": "true or false",
            "pin": 'an Arduino pin: a number (9) or an analog name ("A0")',
            "bools": "a list of true/false, one per wheel channel",
            "parts": "a list of pin tables, one per wheel channel",
            "points": "a list of [x, y] points in m",
        }[self.type]


def _range(field: str, scale: float, message: type[SetConfig] | type[SetPid] = SetConfig) -> tuple[float, float]:
    """The spec's range of `message`'s `field`, in the file's unit (firmware value * scale)."""
    info = next(f for f in message.FIELDS if f.name == field)
    return info.lo * scale, info.hi * scale


def _ranged(key: Key, field: str, scale: float) -> Key:
    """`key` with the range of SET_CONFIG `field` (firmware value * scale = file value)."""
    lo, hi = _range(field, scale)
    return replace(key, lo=lo, hi=hi)


BOARDS = ("uno", "mega2560", "pico", "native")
DRIVE_KINDS = ("differential", "ackermann")
DRIVERS = ("TB6612", "L298N", "BTS7960", "ESC+servo")
DECODING = ("x1", "x2", "x4")
SAFE_STATES = ("coast", "brake", "ramp_down")
FEEDBACK_MODES = ("stream", "lockstep")
LIGHTS = ("front_left", "front_right", "rear_left", "rear_right")
LIGHTS_MODES = ("auto", "off")
MOUNT = (
    Key("x_m", "float", "m", "Mount position ahead of the pose point (REP-103).", 0.0, -10.0, 10.0),
    Key("y_m", "float", "m", "Mount position left of the pose point.", 0.0, -10.0, 10.0),
    Key("z_m", "float", "m", "Mount height above the pose point.", 0.0, -10.0, 10.0),
    Key("yaw_deg", "float", "deg", "Mount yaw, counter-clockwise from the robot's front.", 0.0, -180.0, 180.0),
)
_SERIAL = (
    Key("port", "str", "", "Serial port of the device on the host (empty: chosen when the program starts).", ""),
    Key("baud", "int", "Bd", "Serial speed (0: the device's datasheet default).", 0, 0, 4_000_000),
)

SECTIONS: dict[str, tuple[Key, ...]] = {
    "": (
        Key("name", "str", "", "The robot's name (reported by the firmware, shown by the tools)."),
        Key("description", "str", "", "What the robot is, in one sentence.", ""),
        Key("board", "choice", "", "Which board runs the firmware.", REQUIRED, choices=BOARDS),
        Key(
            "entropy_pin",
            "pin",
            "",
            "Analog pin left open: its noise seeds the boot_id (not read on the Pico: its ring oscillator's).",
            "A0",
        ),
    ),
    "drive": (
        Key("kind", "choice", "", "Differential (two driven wheels) or Ackermann (steered car).", choices=DRIVE_KINDS),
        Key(
            "driver",
            "choice",
            "",
            "Motor driver: a DC driver per wheel, or an RC ESC and a steering servo.",
            choices=DRIVERS,
        ),
        Key(
            "motors",
            "parts",
            "",
            "DC driver pins per wheel channel (left, right): TB6612 pwm, in1, in2, "
            "standby; L298N pwm (ENx), in1, in2; BTS7960 rpwm, lpwm, r_en, l_en.",
            ABSENT,
        ),
        Key("motor_invert", "bools", "", "Per wheel channel: reverse the motor's direction.", ABSENT),
    ),
    "esc": (
        Key("pin", "pin", "", "ESC signal pin (a 16-bit timer channel: Timer1 on the Uno)."),
        _ranged(Key("min_pulse_s", "float", "s", "Full reverse pulse width.", 0.001), "esc_min_us", 1e-6),
        _ranged(Key("neutral_pulse_s", "float", "s", "Neutral pulse width.", 0.0015), "esc_neutral_us", 1e-6),
        _ranged(Key("max_pulse_s", "float", "s", "Full forward pulse width.", 0.002), "esc_max_us", 1e-6),
        _ranged(Key("arm_s", "float", "s", "Neutral held at boot while the ESC arms.", 0.0), "esc_arm_ms", 1e-3),
    ),
    "steering": (
        Key("pin", "pin", "", "Steering servo signal pin (same 16-bit timer as the ESC)."),
        _ranged(
            Key("center_deg", "float", "deg", "Servo angle that steers straight.", 90.0), "steering_center_cdeg", 0.01
        ),
        _ranged(Key("min_deg", "float", "deg", "Smallest servo angle (full right).", 90.0), "steering_min_cdeg", 0.01),
        _ranged(Key("max_deg", "float", "deg", "Largest servo angle (full left).", 90.0), "steering_max_cdeg", 0.01),
        _ranged(Key("step_deg", "float", "deg", "Servo angle step (0: continuous).", 0.0), "steering_step_cdeg", 0.01),
        _ranged(Key("min_pulse_s", "float", "s", "Pulse width at 0 deg.", 0.0005), "servo_min_us", 1e-6),
        _ranged(Key("max_pulse_s", "float", "s", "Pulse width at 180 deg.", 0.0025), "servo_max_us", 1e-6),
    ),
    "encoders": (
        Key("pins", "parts", "", "Quadrature encoder pins a, b per wheel channel (both must interrupt).", ABSENT),
        _ranged(
            Key("counts_per_rev", "int", "counts/rev", "Counts per wheel revolution after decoding and gearing."),
            "encoder_cpr",
            1,
        ),
        Key("decoding", "choice", "", "Edges counted per encoder cycle: x1, x2 or x4.", "x4", choices=DECODING),
        Key("invert", "bools", "", "Per wheel channel: reverse the count direction.", ABSENT),
    ),
    "geometry": (
        _ranged(Key("wheel_diameter_m", "float", "m", "Driven wheel diameter."), "wheel_diameter_um", 1e-6),
        Key("track_m", "float", "m", "Distance between the left and right wheels.", REQUIRED, 0.01, 10.0),
        Key("wheelbase_m", "float", "m", "Distance between the axles (Ackermann; 0 for differential).", 0.0, 0.0, 10.0),
        Key(
            "gear_ratio",
            "float",
            "",
            "Motor turns per wheel turn (the emulator's gearbox; counts_per_rev includes it).",
            1.0,
            0.01,
            1000.0,
        ),
    ),
    "limits": (
        _ranged(
            Key("max_wheel_speed_m_s", "float", "m/s", "Fastest wheel speed the firmware commands."),
            "max_wheel_speed_mm_s",
            1e-3,
        ),
        _ranged(
            Key("accel_m_s2", "float", "m/s^2", "Largest setpoint increase per second.", 1.0), "accel_limit_mm_s2", 1e-3
        ),
        _ranged(
            Key("decel_m_s2", "float", "m/s^2", "Largest setpoint decrease per second.", 2.0), "decel_limit_mm_s2", 1e-3
        ),
        _ranged(
            Key("max_effort", "float", "", "Largest motor effort, as a fraction of full.", 1.0),
            "max_effort_permille",
            1e-3,
        ),
        _ranged(
            Key("watchdog_s", "float", "s", "Silence after which the firmware stops the motors.", 0.25),
            "watchdog_ms",
            1e-3,
        ),
        Key(
            "safe_state",
            "choice",
            "",
            "Motor behaviour when stopped by the watchdog or disarmed.",
            "brake",
            choices=SAFE_STATES,
        ),
    ),
    # Firmware gains are per mille of full effort per mm/s: numerically the same as fraction per m/s.
    "pid": (
        Key(
            "kp",
            "gain",
            "effort/(m/s)",
            "Proportional gain (effort as a fraction of full).",
            1.0,
            *_range("kp", 1, SetPid),
        ),
        Key("ki", "gain", "effort/m", "Integral gain.", 0.0, *_range("ki", 1, SetPid)),
        Key("kd", "gain", "effort/(m/s^2)", "Derivative gain, on the measurement.", 0.0, *_range("kd", 1, SetPid)),
        Key("kf", "gain", "effort/(m/s)", "Feed-forward gain on the setpoint.", 0.0, *_range("kf", 1, SetPid)),
        Key(
            "ks",
            "gain",
            "permille",
            "Static-friction feed-forward (permille of full effort, 70 = 7 %): the effort that keeps a wheel "
            "turning at the lowest speeds, added with the setpoint's sign.",
            0.0,
            *_range("ks", 1, SetPid),
        ),
    ),
    "feedback": (
        Key(
            "mode",
            "choice",
            "",
            "How FEEDBACK is sent: at a rate, or one per setpoint.",
            "stream",
            choices=FEEDBACK_MODES,
        ),
        _ranged(Key("rate_hz", "float", "Hz", "FEEDBACK rate in stream mode.", 50.0), "feedback_hz", 1.0),
        Key("lockstep", "bool", "", "The firmware offers lockstep mode (capability LOCKSTEP).", False),
    ),
    "lights": (
        *(Key(n, "pin", "", f"Turn-signal LED {n.replace('_', ' ')}.") for n in LIGHTS),
        Key(
            "mode",
            "choice",
            "",
            "The turn signals at power-up and at each new session: from the motion state, or dark "
            "(a host changes it with SET_LIGHTS).",
            "auto",
            choices=LIGHTS_MODES,
        ),
    ),
    "sensors.lidar": (Key("model", "str", "", "Lidar model (protocol/spec/sensors.toml)."), *_SERIAL, *MOUNT),
    "sensors.imu": (Key("model", "str", "", "IMU model (protocol/spec/sensors.toml)."), *_SERIAL, *MOUNT),
    "sensors.camera": (
        Key("model", "str", "", "Camera model (protocol/spec/sensors.toml).", "pi-camera-v2"),
        Key("source", "str", "", "Where frames come from: a device, file or URL (empty: chosen at start).", ""),
        Key("width", "int", "px", "Image width.", 320, 16, 8192),
        Key("height", "int", "px", "Image height.", 240, 16, 8192),
        Key("hfov_deg", "float", "deg", "Horizontal field of view (0: the model's).", 0.0, 0.0, 179.0),
        Key("fx", "float", "px", "Focal length in x (intrinsics; 0: from the field of view).", 0.0, 0.0, 1e5),
        Key("fy", "float", "px", "Focal length in y (0: fx).", 0.0, 0.0, 1e5),
        Key("cx", "float", "px", "Principal point x (0: the image centre).", 0.0, 0.0, 8192.0),
        Key("cy", "float", "px", "Principal point y (0: the image centre).", 0.0, 0.0, 8192.0),
        *MOUNT,
    ),
    "footprint": (
        Key(
            "radius_m",
            "float",
            "m",
            "The body as a disc of this radius (one of radius_m, box, polygon_m).",
            ABSENT,
            0.01,
            10.0,
        ),
        Key("length_m", "float", "m", "The body as a box: length along x (with width_m).", ABSENT, 0.01, 20.0),
        Key("width_m", "float", "m", "The body as a box: width along y (with length_m).", ABSENT, 0.01, 20.0),
        Key("polygon_m", "points", "m", "The body as a polygon: [x, y] corners around the pose point.", ABSENT),
        Key("x_m", "float", "m", "Disc or box centre ahead of the pose point.", 0.0, -10.0, 10.0),
    ),
    # The emulator's physics of the robot: what the firmware cannot know. Read by the emulator
    # (emulator/plant/params.py builds its motor, body, ESC and servo models from these); a section
    # left out is the nearest reference robot's. The gearbox is [geometry] gear_ratio; the ESC's
    # and servo's pulses are [esc]'s and [steering]'s.
    "emulator.motor": (
        Key("supply_v", "float", "V", "Battery voltage at the bridge at full duty.", REQUIRED, 0.1, 100.0),
        Key("resistance_ohm", "float", "ohm", "Winding (plus bridge) resistance.", REQUIRED, 0.001, 1000.0),
        Key("inductance_h", "float", "H", "Winding inductance (electrical time constant L/R).", REQUIRED, 0.0, 1.0),
        Key(
            "ke_v_s_rad",
            "float",
            "V s/rad",
            "Back-EMF constant at the motor shaft (the torque constant in N m/A; 60 / (2 pi kV) for a kV rating).",
            REQUIRED,
            1e-5,
            10.0,
        ),
        Key("efficiency", "float", "", "Gearbox efficiency.", REQUIRED, 0.01, 1.0),
        Key(
            "rotor_inertia_kg_m2",
            "float",
            "kg m^2",
            "Rotor inertia at the motor shaft (reflected to the wheel as J * gear_ratio^2).",
            REQUIRED,
            0.0,
            1.0,
        ),
        Key("coulomb_nm", "float", "N m", "Dry friction of motor and gearbox, at the wheel.", REQUIRED, 0.0, 100.0),
        Key("viscous_nm_s_rad", "float", "N m s/rad", "Viscous friction at the wheel.", REQUIRED, 0.0, 10.0),
        Key("deadband", "float", "", "Duty fraction below which the bridge gives no voltage.", REQUIRED, 0.0, 0.5),
        Key("current_limit_a", "float", "A", "Driver current limit (absent: none).", ABSENT, 0.01, 1000.0),
    ),
    "emulator.body": (
        Key("mass_kg", "float", "kg", "Mass of the robot.", REQUIRED, 0.01, 1000.0),
        Key("yaw_inertia_kg_m2", "float", "kg m^2", "Inertia about the vertical axis.", REQUIRED, 1e-6, 1000.0),
        Key(
            "wheel_inertia_kg_m2",
            "float",
            "kg m^2",
            "Inertia of one driven wheel (or the driven axle), without the motor.",
            REQUIRED,
            0.0,
            10.0,
        ),
        Key(
            "drive_load_fraction",
            "float",
            "",
            "Share of the weight on the driven wheels (the rest on casters or the steered axle).",
            REQUIRED,
            0.01,
            1.0,
        ),
        Key(
            "rolling_resistance", "float", "", "Rolling resistance coefficient of the driven tyres.", REQUIRED, 0.0, 1.0
        ),
        Key("mu", "float", "", "Tyre-ground friction coefficient.", 0.8, 0.01, 10.0),
    ),
    "emulator.esc": (
        Key(
            "calibration_tolerance_us",
            "int",
            "us",
            "How far from its nominal neutral a pulse may be and still be learned as neutral.",
            100,
            0,
            500,
        ),
        Key("neutral_band_us", "int", "us", "Half-width of the stop band around the learned neutral.", 30, 0, 500),
        Key("calibration_ms", "int", "ms", "Steady neutral needed before the ESC arms.", 2000, 0, 60000),
        Key("signal_timeout_ms", "int", "ms", "No pulse for this long: output off, calibration again.", 100, 1, 60000),
        Key("drag_brake", "float", "", "Braking at neutral: 0 coasts, 1 brakes fully.", 0.0, 0.0, 1.0),
    ),
    "emulator.servo": (
        Key("resolution_deg", "float", "deg", "Smallest step the servo resolves.", 0.5, 0.0, 10.0),
        Key("slew_deg_s", "float", "deg/s", "Top speed of the horn.", 400.0, 1.0, 10000.0),
        Key("linkage_ratio", "float", "", "Front-wheel angle per horn angle.", 1.0, 0.01, 10.0),
        Key(
            "travel_margin_deg",
            "float",
            "deg",
            "Mechanical travel beyond [steering] min_deg..max_deg.",
            5.0,
            0.0,
            90.0,
        ),
    ),
    "firmware": (
        Key(
            "example",
            "str",
            "",
            "The library's example sketch the firmware is built from (empty: the one a reference robot of the "
            "same drive and driver names).",
            "",
        ),
    ),
    "calibration": (
        Key(
            "wheel_diameter_m",
            "float",
            "m",
            "Measured wheel diameter (overrides geometry's).",
            ABSENT,
            *_range("wheel_diameter_um", 1e-6),
        ),
        Key("track_m", "float", "m", "Measured effective track (overrides geometry's).", ABSENT, 0.01, 10.0),
        Key(
            "counts_per_rev",
            "int",
            "counts/rev",
            "Measured counts per wheel revolution.",
            ABSENT,
            *_range("encoder_cpr", 1),
        ),
        Key("steering_trim_deg", "float", "deg", "Added to steering.center_deg to drive straight.", 0.0, -45.0, 45.0),
    ),
}
"""Section ("" = top level, "sensors.lidar" = [sensors.lidar]) -> its keys, in file order."""


def key(section: str, name: str) -> Key:
    return next(k for k in SECTIONS[section] if k.name == name)
