"""Hypothesis strategies for RoverLink messages, frames and byte streams.

Every strategy is derived from the spec metadata on the generated classes (`cls.FIELDS`), so a
message added to `protocol/spec/roverlink.toml` is covered as soon as the code is regenerated; no
strategy is written by hand for a particular message.

What is generated is always *valid*: it encodes without error and decodes back to an equal value.

* integers lie in the field's range (the spec's ``min``/``max``, else the wire type's);
* ``f32`` values are finite, in range and exactly representable as IEEE-754 single precision
  (they survive ``struct.pack("<f", ...)`` unchanged, so decoded messages compare equal);
* enums are members of their enum, flags any combination of their members;
* ``char[..N]`` fields are ASCII strings of at most N characters (NUL included), ``u8[..N]``
  fields bytes of at most N;
* fixed arrays are tuples of exactly ``count`` elements.

Fuzz your own code with them, e.g. a handler that must accept any telemetry the board can send
(here the SDK's own odometry, fed every FEEDBACK a board may send; a test that fails shows the
smallest one that breaks it):

    >>> from hypothesis import given, settings
    >>> from host_sdk import messages
    >>> from host_sdk.odometry import Odometry
    >>> from host_sdk.profiles import kinematics_for
    >>> from host_sdk.testing import strategies as rls
    >>> @settings(max_examples=20)
    ... @given(rls.message(messages.Feedback))
    ... def test_odometry_starts_where_the_first_sample_is(fb: messages.Feedback) -> None:
    ...     odometry = Odometry(kinematics_for("diffdrive-tb6612"))
    ...     pose = odometry.update(fb.encoder_counts, fb.mcu_time_us)
    ...     assert (pose.x_m, pose.y_m) == (0.0, 0.0)
    >>> test_odometry_starts_where_the_first_sample_is()

and code that reads bytes, with the frames that were sent and the bytes a port carries for them::

    @given(rls.streams(max_frames=20))
    def test_reader_sees_every_frame(stream: rls.Stream) -> None:
        reader = MyReader()
        reader.on_bytes(stream.wire)
        assert reader.received == [f.message for f in stream.frames]

``frames()`` and ``streams()`` give what a port would carry, for testing code that reads bytes.

``drive_commands(profile)`` and ``command_sequences(profile)`` give what a robot program sends:
`Twist`, `WheelSpeeds` or `AckermannCommand` values (host_sdk.testing.commands) within the
robot's limits (its firmware's default configuration), or beyond them with ``in_range=False``;
a sequence is a list of `Step` (command, seconds) to drive with `run_steps` on an
`emulated_robot` (docs/sdk.md, "Property tests").

hypothesis is needed only here: ``import host_sdk`` never imports it (install the ``dev`` extra).
"""

from __future__ import annotations

import enum
import functools
import math
import operator
import struct
from collections.abc import Iterable
from typing import Any, NamedTuple, TypeVar, cast

from hypothesis import strategies as st

from host_sdk.framing import Frame, encode_frame
from host_sdk.kinematics import Ackermann, DiffDrive
from host_sdk.limits import DriveLimits
from host_sdk.profiles import RobotProfile, get_profile, kinematics_for
from host_sdk.testing.commands import AckermannCommand, DriveCommand, Step, Twist, WheelSpeeds
from protocol.codec.message import FieldInfo, Message
from protocol.generated.messages import ALL_MESSAGES

__all__ = [
    "AckermannCommand",
    "DriveCommand",
    "Step",
    "Stream",
    "Twist",
    "WheelSpeeds",
    "command_sequences",
    "drive_commands",
    "field_values",
    "frames",
    "message",
    "messages",
    "seqs",
    "streams",
]

M = TypeVar("M", bound=Message)

_F32 = struct.Struct("<f")
_F32_MAX = 3.4028234663852886e38


class Stream(NamedTuple):
    """Frames in the order they were sent, and the bytes a port would carry for them."""

    frames: list[Frame]
    """(message, seq) pairs; each compares equal to the `Frame` a decoder yields for it."""
    wire: bytes
    """Every frame encoded with `encode_frame`, back to back (each ends with its 0x00)."""


def _to_f32(x: float) -> float:
    """`x` rounded to the nearest single-precision value (what goes on the wire)."""
    rounded: float = _F32.unpack(_F32.pack(x))[0]
    return rounded


def _f32_bounds(lo: float, hi: float) -> tuple[float, float]:
    """The smallest and largest f32 values inside [lo, hi] (the spec's bounds may not be f32)."""
    lo, hi = max(lo, -_F32_MAX), min(hi, _F32_MAX)
    lo32, hi32 = _to_f32(lo), _to_f32(hi)
    if lo32 < lo:  # rounding to nearest is off by at most half an ulp: one step fixes it
        lo32 = _next_f32(lo32, up=True)
    if hi32 > hi:
        hi32 = _next_f32(hi32, up=False)
    if lo32 > hi32:
        raise ValueError(f"no f32 value lies in {lo!r}..{hi!r}")
    return lo32, hi32


def _next_f32(x: float, *, up: bool) -> float:
    """The f32 neighbour of the f32 value `x` (bit pattern plus or minus one)."""
    (bits,) = struct.unpack("<i", _F32.pack(x))
    if x == 0.0:
        return 1.401298464324817e-45 if up else -1.401298464324817e-45
    step = 1 if (x > 0) == up else -1
    neighbour: float = _F32.unpack(struct.pack("<i", bits + step))[0]
    return neighbour


def _scalar(info: FieldInfo) -> st.SearchStrategy[Any]:
    """Values of one element of the field (the field itself unless it is an array)."""
    if info.kind == "int":
        return st.integers(min_value=int(info.lo), max_value=int(info.hi))
    if info.kind == "float":
        lo, hi = _f32_bounds(float(info.lo), float(info.hi))
        return st.floats(min_value=lo, max_value=hi, width=32, allow_nan=False, allow_infinity=False).map(_to_f32)
    if info.kind == "enum":
        if info.enum is None:
            raise TypeError(f"enum field {info.name} has no enum class")
        return st.sampled_from(list(cast("Iterable[enum.IntEnum]", info.enum)))
    if info.kind == "flags":
        if info.enum is None:
            raise TypeError(f"flags field {info.name} has no enum class")
        flag_cls = cast("type[enum.IntFlag]", info.enum)
        members = [m for m in flag_cls if not int(m) & ~int(info.hi)]
        empty = flag_cls(0)
        if not members:
            return st.just(empty)
        return st.sets(st.sampled_from(members)).map(lambda bits: functools.reduce(operator.or_, bits, empty))
    raise ValueError(f"field {info.name}: no strategy for kind {info.kind!r}")


@functools.cache
def field_values(info: FieldInfo) -> st.SearchStrategy[Any]:
    """Valid values of one field, as its message class expects them (tuples for fixed arrays).

    `FieldInfo` is what each generated class lists in `FIELDS`; e.g. ``field_values(
    messages.SetAckermann.FIELDS[1])`` gives steering angles in -1571..1571.
    """
    if info.kind == "str":
        alphabet = st.characters(min_codepoint=int(info.lo), max_codepoint=min(int(info.hi), 127))
        return st.text(alphabet=alphabet, max_size=info.max_len)
    if info.kind == "bytes":
        if info.count is not None:
            return st.binary(min_size=info.count, max_size=info.count)
        return st.binary(max_size=info.max_len)
    element = _scalar(info)
    if info.count is not None:
        return st.tuples(*[element] * info.count)
    return element


# Built once per class (and per tuple of classes): hypothesis strategies are immutable and lazy.
_BY_CLASS: dict[type[Message], st.SearchStrategy[Message]] = {}
_BY_CLASSES: dict[tuple[type[Message], ...], st.SearchStrategy[Message]] = {}


def _message(cls: type[Message]) -> st.SearchStrategy[Message]:
    strategy = _BY_CLASS.get(cls)
    if strategy is None:
        by_name = {info.name: field_values(info) for info in cls.FIELDS}
        strategy = _BY_CLASS[cls] = st.fixed_dictionaries(by_name).map(lambda values: cls(**values))
    return strategy


def message(cls: type[M]) -> st.SearchStrategy[M]:
    """Valid instances of one message class, e.g. ``message(messages.SetWheelSpeeds)``.

    The strategy is built once per class from ``cls.FIELDS`` and cached.
    """
    return cast("st.SearchStrategy[M]", _message(cls))


def _messages(classes: tuple[type[Message], ...]) -> st.SearchStrategy[Message]:
    strategy = _BY_CLASSES.get(classes)
    if strategy is None:
        if not classes:
            raise ValueError("messages() needs at least one message class")
        strategy = _BY_CLASSES[classes] = st.one_of([_message(cls) for cls in classes])
    return strategy


def messages(classes: Iterable[type[Message]] | None = None) -> st.SearchStrategy[Message]:
    """A valid message of any class (or of one of `classes`), e.g. only what the board sends::

    messages(c for c in ALL_MESSAGES if c.DIRECTION is Direction.MCU_TO_HOST)
    """
    return _messages(tuple(ALL_MESSAGES if classes is None else classes))


def seqs() -> st.SearchStrategy[int]:
    """Sequence numbers: 0..255."""
    return st.integers(min_value=0, max_value=0xFF)


def frames(of: st.SearchStrategy[Message] | None = None) -> st.SearchStrategy[Frame]:
    """(message, seq) pairs, as `Frame` tuples: what `FrameDecoder.feed` yields for a good frame.

    `of` defaults to `messages()`; pass e.g. ``message(messages.Feedback)`` to fix the class.
    """
    return st.builds(Frame, messages() if of is None else of, seqs())


def _stream(items: list[Frame]) -> Stream:
    return Stream(items, b"".join([encode_frame(msg, seq) for msg, seq in items]))


def streams(
    of: st.SearchStrategy[Frame] | None = None, *, min_frames: int = 0, max_frames: int = 10
) -> st.SearchStrategy[Stream]:
    """A `Stream`: frames (from `of`, default `frames()`) and their concatenated wire bytes.

    Unpacks as a pair: ``sent, wire = data.draw(streams())``.
    """
    items = st.lists(frames() if of is None else of, min_size=min_frames, max_size=max_frames)
    return items.map(_stream)


# == drive commands ================================================================================
_BEYOND = 3.0
"""Out-of-range values reach this many times the limit."""
_PAST = 1e-3
"""Out-of-range values are at least this far past the limit (well past the checks' rounding slack)."""


def _within(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(min_value=lo, max_value=hi, allow_nan=False, allow_infinity=False)


def _beyond(limit: float) -> st.SearchStrategy[float]:
    """Values of either sign past `limit` (>= 0) by at least `_PAST`."""
    past = _within(limit + _PAST, max(limit, _PAST) * _BEYOND + _PAST)
    return st.one_of(past, past.map(operator.neg))


def _diff_commands(kin: DiffDrive, limits: DriveLimits, top: float, in_range: bool) -> st.SearchStrategy[DriveCommand]:
    if in_range:
        wheels = st.builds(WheelSpeeds, _within(-top, top), _within(-top, top))
        return st.one_of(wheels, wheels.map(lambda w: Twist(*kin.twist(w.left_m_s, w.right_m_s))))
    limit, anything = limits.max_speed_m_s, _within(-_BEYOND * top, _BEYOND * top)
    fast = _beyond(limit)
    return st.one_of(
        st.builds(WheelSpeeds, fast, anything),
        st.builds(WheelSpeeds, anything, fast),
        st.builds(Twist, fast, _within(-1.0, 1.0)),
    )


def _ackermann_commands(
    kin: Ackermann, limits: DriveLimits, top: float, in_range: bool
) -> st.SearchStrategy[DriveCommand]:
    right, left = limits.steer_right_rad, limits.steer_left_rad
    if in_range:
        steered = st.builds(AckermannCommand, _within(-top, top), _within(-right, left))
        as_twist = steered.map(lambda c: Twist(c.speed_m_s, kin.turn_rate(c.speed_m_s, c.steering_rad)))
        return st.one_of(steered, as_twist)
    speed, steer = _within(-top, top), _within(-right, left)
    too_far = st.one_of(_within(left + _PAST, math.pi), _within(-math.pi, -right - _PAST))
    return st.one_of(
        st.builds(AckermannCommand, _beyond(limits.max_speed_m_s), steer),
        st.builds(AckermannCommand, speed, too_far),
    )


def drive_commands(
    profile: str | RobotProfile = "diffdrive-tb6612", *, in_range: bool = True, max_speed_m_s: float | None = None
) -> st.SearchStrategy[DriveCommand]:
    """Drive commands for the reference robot `profile`, against its firmware's default limits
    (`DriveLimits.of(profile.config)`: what an ``emu://`` robot with a saved EEPROM has).

    In range (the default): `WheelSpeeds` and `Twist` for a differential drive, `AckermannCommand`
    and `Twist` for a steered robot, every wheel within ``max_speed_m_s`` (default: the limit),
    the steering within the servo's travel: the robot accepts each one without clamping.
    ``in_range=False``: commands with a speed or a steering angle beyond the limit, which the
    robot refuses (CommandRangeError) or, with ``clamp=True``, brings inside.

    >>> from hypothesis import given
    >>> @given(drive_commands("picar"))
    ... def test_a_steered_robot_gets_no_wheel_speeds(command: DriveCommand) -> None:
    ...     assert isinstance(command, (AckermannCommand, Twist))
    >>> test_a_steered_robot_gets_no_wheel_speeds()
    """
    prof = profile if isinstance(profile, RobotProfile) else get_profile(profile, argument="profile")
    limits = DriveLimits.of(prof.config)
    top = limits.max_speed_m_s if max_speed_m_s is None else min(max_speed_m_s, limits.max_speed_m_s)
    if top < 0:
        raise ValueError(f"max_speed_m_s must be >= 0, not {max_speed_m_s!r}")
    kin = kinematics_for(prof)
    if isinstance(kin, DiffDrive):
        return _diff_commands(kin, limits, top, in_range)
    return _ackermann_commands(kin, limits, top, in_range)


def command_sequences(
    profile: str | RobotProfile = "diffdrive-tb6612",
    *,
    commands: st.SearchStrategy[DriveCommand] | None = None,
    min_steps: int = 1,
    max_steps: int = 5,
    min_duration_s: float = 0.05,
    max_duration_s: float = 1.0,
) -> st.SearchStrategy[list[Step]]:
    """Lists of `Step` (command, duration): `commands` (default ``drive_commands(profile)``) each
    held `min_duration_s`..`max_duration_s`, for `run_steps(robot, steps)`."""
    durations = _within(min_duration_s, max_duration_s)
    steps = st.builds(Step, drive_commands(profile) if commands is None else commands, durations)
    return st.lists(steps, min_size=min_steps, max_size=max_steps)
