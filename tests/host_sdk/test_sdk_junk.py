"""Generated junk thrown at every public callable of the SDK.

Each call must either succeed (with finite numbers, if it returns numbers) or raise a RoverLinkError;
when an argument is bad that error is an ArgumentError naming one of the arguments passed. Never
another exception type (AttributeError, TypeError, OverflowError from deep inside), never a hang.
Values are drawn per argument from a mix of junk (None, bools, huge and non-finite numbers,
strings, bytes, containers, objects) and valid values, so both outcomes are exercised.
"""

from __future__ import annotations

import math
import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from host_sdk import Robot, messages
from host_sdk.errors import (
    ArgumentError,
    EncodeError,
    FeedbackTimeoutError,
    KinematicsError,
    NackError,
    RoverLinkError,
    TransportError,
    UnsupportedError,
)
from host_sdk.framing import FrameDecoder, encode_frame
from host_sdk.kinematics import Ackermann, Arc, DiffDrive
from host_sdk.odometry import Odometry, integrate_arc
from host_sdk.profiles import PROFILES, get_profile, kinematics_for, steering_angles, steering_limits
from host_sdk.timesync import ClockSync, Unwrapper

JUNK = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(2**70), 2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([math.nan, math.inf, -math.inf, 2**64, -(2**64), 1e300, -1e300, 10**400, 1j, 0, -1]),
    st.text(max_size=4),
    st.binary(max_size=4),
    st.lists(st.integers(-3, 3), max_size=3),
    st.sampled_from([object(), print, (), {}, [1.0, 2.0], Arc(1.0, 0.1), b"\x00\x00"]),
)


def _number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def seconds_junk() -> st.SearchStrategy[Any]:
    """Junk for a duration: anything but a valid long wait (that would only be slow, not wrong)."""
    return JUNK.filter(lambda v: not (_number(v) and 0.05 < v <= 86_400))


def arg(valid: st.SearchStrategy[Any], junk: st.SearchStrategy[Any] = JUNK) -> st.SearchStrategy[Any]:
    return st.one_of(valid, junk)


class Hang(Exception):
    pass


@contextmanager
def no_hang(seconds: int = 20) -> Iterator[None]:
    def alarm(_signum: int, _frame: object) -> None:
        raise Hang(f"the call did not return within {seconds} s")

    old = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def _finite(result: object) -> bool:
    if isinstance(result, float):
        return math.isfinite(result)
    if isinstance(result, (tuple, list)):
        return all(_finite(r) for r in result)
    for name in ("x_m", "y_m", "theta_rad", "distance_m", "dtheta_rad"):
        if isinstance(getattr(result, name, None), float) and not math.isfinite(getattr(result, name)):
            return False
    return True


def outcome(call: Callable[[], Any], passed: dict[str, Any], allowed: tuple[type[BaseException], ...] = ()) -> None:
    """Run `call`; fail unless it succeeds finitely or raises an SDK error naming an argument in `passed`."""
    try:
        with no_hang():
            result = call()
    except (ArgumentError, EncodeError) as err:
        named = err.argument if isinstance(err, ArgumentError) else err.field  # EncodeError: a message field
        root = named.split("[")[0].split(".")[0]
        assert root in passed, f"{err!r} names {named!r}, not one of the arguments {sorted(passed)}"
        assert named in str(err)
        return
    except allowed:
        return
    except RoverLinkError as err:
        pytest.fail(f"{type(err).__name__} without naming an argument for {passed!r}: {err}")
    assert _finite(result), f"{passed!r} gave a non-finite result {result!r}"


def kwargs(**strategies: st.SearchStrategy[Any]) -> st.SearchStrategy[dict[str, Any]]:
    """A dict of every named argument."""
    return st.fixed_dictionaries(strategies)


SPEED = st.floats(-0.3, 0.3)
CLAMP = st.one_of(st.none(), st.booleans())
HOLD = st.one_of(st.none(), st.floats(0.01, 0.2))
SHORT = st.floats(0.001, 0.05)
CALLBACK = st.just(lambda *args: None)
CONFIG_FIELDS = [f.name for f in messages.SetConfig.FIELDS]


def robot_calls(robot: Robot) -> list[tuple[Callable[..., Any], st.SearchStrategy[dict[str, Any]], tuple[type, ...]]]:
    speed = arg(SPEED)
    clamp, hold, short = arg(CLAMP), arg(HOLD, seconds_junk()), arg(SHORT, seconds_junk())

    def subscribe(method: Callable[..., Callable[[], None]]) -> Callable[..., None]:
        return lambda **kw: method(**kw)()  # subscribe, then unsubscribe again

    def stream(**kw: Any) -> Any:
        return next(robot.feedback_stream(**kw))

    def set_clamp(clamp: Any) -> None:
        robot.clamp = clamp

    return [
        (robot.drive, kwargs(linear_m_s=speed, angular_rad_s=arg(st.floats(-1, 1)), clamp=clamp, hold_s=hold), ()),
        (robot.set_wheel_speeds, kwargs(left_m_s=speed, right_m_s=speed, clamp=clamp, hold_s=hold), ()),
        (
            robot.drive_ackermann,
            kwargs(speed_m_s=speed, steering_rad=speed, clamp=clamp, hold_s=hold),
            (UnsupportedError,),
        ),
        (robot.arm, kwargs(timeout_s=short, wait_esc=arg(st.booleans())), ()),
        (robot.wait_feedback, kwargs(timeout_s=short), (FeedbackTimeoutError,)),
        (stream, kwargs(timeout_s=short), (FeedbackTimeoutError,)),
        (robot.sleep, kwargs(seconds=arg(st.floats(0, 0.05), seconds_junk())), ()),
        (subscribe(robot.on_feedback), kwargs(callback=arg(CALLBACK)), ()),
        (subscribe(robot.on_reset), kwargs(callback=arg(CALLBACK)), ()),
        (subscribe(robot.on_failsafe), kwargs(callback=arg(CALLBACK)), ()),
        (subscribe(robot.on_log), kwargs(callback=arg(CALLBACK)), ()),
        (robot.pid, kwargs(wheel=arg(st.integers(0, 1))), ()),
        (
            robot.set_pid,
            kwargs(
                **{g: arg(st.one_of(st.none(), st.floats(0, 5))) for g in ("kp", "ki", "kd", "kf")},
                wheel=arg(st.one_of(st.none(), st.integers(0, 1))),
            ),
            (),
        ),
        (robot.mcu_to_host_s, kwargs(mcu_time_us=arg(st.integers(0, 2**40))), ()),
        (
            robot.odometry.reset,
            kwargs(x_m=arg(st.floats(-5, 5)), y_m=arg(st.floats(-5, 5)), theta_rad=arg(st.floats(-5, 5))),
            (),
        ),
        (set_clamp, kwargs(clamp=arg(st.booleans())), ()),
    ]


@pytest.fixture(scope="module")
def junk_robot() -> Iterator[Robot]:
    with Robot.connect("emu://diffdrive-tb6612?clock=virtual") as robot:
        yield robot


@settings(max_examples=300)
@given(data=st.data())
def test_junk_to_every_robot_method(junk_robot: Robot, data: st.DataObject) -> None:
    robot = junk_robot
    if not robot.armed:
        robot.arm()
    calls = robot_calls(robot)
    method, args_strategy, allowed = data.draw(st.sampled_from(calls), label="method")
    passed = data.draw(args_strategy, label="arguments")
    outcome(lambda: method(**passed), passed, allowed)


@settings(max_examples=60)
@given(
    changes=st.dictionaries(
        st.one_of(st.sampled_from(CONFIG_FIELDS), st.sampled_from(["bogus", "kp"])),
        st.one_of(JUNK, st.integers(0, 3), st.integers(50, 2000)),
        min_size=1,
        max_size=3,
    )
)
def test_junk_to_set_config(junk_robot: Robot, changes: dict[str, Any]) -> None:
    saved = junk_robot.config
    try:
        outcome(lambda: junk_robot.set_config(**changes), changes, (NackError,))
    finally:
        junk_robot.set_config(**saved.fields())  # the next example starts from the same board


CONNECT = kwargs(
    profile=arg(st.sampled_from(sorted(PROFILES))),
    kinematics=arg(st.just(DiffDrive(0.032, 0.2, 1560))),
    baud=arg(st.sampled_from([9600, 115200])),
    watchdog_s=arg(st.floats(0.05, 2.0)),
    mode=arg(st.sampled_from(["stream", "lockstep"])),
    feedback_hz=arg(st.integers(0, 100)),
    timeout_s=arg(st.floats(1.0, 5.0), seconds_junk()),
    clamp=arg(st.booleans()),
    auto_rearm=arg(st.booleans()),
    paced=arg(st.booleans()),
    command_timeout_s=arg(st.one_of(st.none(), st.floats(0.05, 1.0)), seconds_junk()),
    request_timeout_s=arg(st.floats(0.05, 0.5), seconds_junk()),
    request_tries=arg(st.integers(1, 5)),
    transport=st.sampled_from([None, "emu://", 3]),
)
URLS = st.sampled_from(
    [
        "emu://diffdrive-tb6612?clock=virtual",
        "emu://picar?clock=virtual",
        None,
        3,
        b"emu://",
        "",
        "emu://?bogus=1",
        "emu://nosuchrobot?clock=virtual",
        "emu://?seed=-1&clock=virtual",
        "/nonexistent/ttyACM9",
    ]
)


@settings(max_examples=60)
@given(url=URLS, options=CONNECT)
def test_junk_to_connect(url: Any, options: dict[str, Any]) -> None:
    def connect() -> None:
        Robot.connect(url, **options).close()

    # A port that does not open is a TransportError naming it; a mode or kinematics the firmware
    # cannot do is UnsupportedError (it names `mode` or the kinematics).
    outcome(connect, {"url": url, **options}, (TransportError, UnsupportedError))


# -- kinematics, odometry, time sync, profiles, codec ----------------------------------------------
LENGTH, COUNT = st.floats(0.01, 1.0), st.integers(1, 5000)
DIFF = DiffDrive(0.032, 0.2, 1560)
CAR = Ackermann(0.26, 0.0325, 720, 0.5)


def module_calls() -> list[tuple[Callable[..., Any], st.SearchStrategy[dict[str, Any]], tuple[type, ...]]]:
    speed, rate = arg(st.floats(-2, 2)), arg(st.floats(-3, 3))
    counts = arg(st.integers(-(10**6), 10**6))
    steer = arg(st.floats(-1.0, 1.0))
    odo = Odometry(DIFF)
    clock = ClockSync()
    decoder = FrameDecoder()
    valid_msg = st.just(messages.SetWheelSpeeds(1, 2))
    return [
        (DiffDrive, kwargs(wheel_radius_m=arg(LENGTH), track_m=arg(LENGTH), counts_per_rev=arg(COUNT)), ()),
        (
            Ackermann,
            kwargs(
                wheelbase_m=arg(LENGTH),
                wheel_radius_m=arg(LENGTH),
                counts_per_rev=arg(COUNT),
                max_steering_rad=arg(st.floats(0.1, 1.2)),
            ),
            (),
        ),
        (DIFF.wheel_speeds, kwargs(linear_m_s=speed, angular_rad_s=rate, max_wheel_m_s=arg(st.floats(0, 2))), ()),
        (DIFF.twist, kwargs(left_m_s=speed, right_m_s=speed), ()),
        (DIFF.arc, kwargs(left_counts=counts, right_counts=counts), ()),
        (CAR.steering_for, kwargs(linear_m_s=speed, angular_rad_s=rate), (KinematicsError,)),
        (CAR.steering_angle, kwargs(linear_m_s=speed, angular_rad_s=rate), ()),
        (CAR.turn_rate, kwargs(linear_m_s=speed, steering_rad=steer), ()),
        (CAR.arc, kwargs(counts=counts, steering_rad=steer), ()),
        (Odometry, kwargs(kinematics=arg(st.just(CAR))), ()),
        (odo.reset, kwargs(x_m=arg(st.floats(-5, 5)), y_m=arg(st.floats(-5, 5)), theta_rad=arg(st.floats(-5, 5))), ()),
        (
            odo.update,
            kwargs(
                counts=arg(st.tuples(st.integers(0, 10**6), st.integers(0, 10**6))),
                mcu_time_us=arg(st.integers(0, 2**40)),
                steering_rad=steer,
            ),
            (),
        ),
        (
            integrate_arc,
            kwargs(
                x=arg(st.floats(-5, 5)),
                y=arg(st.floats(-5, 5)),
                theta=arg(st.floats(-5, 5)),
                arc=arg(st.just(Arc(0.1, 0.2))),
            ),
            (),
        ),
        (Unwrapper, kwargs(bits=arg(st.integers(2, 64))), ()),
        (Unwrapper(16), kwargs(raw=arg(st.integers(0, 65535))), ()),
        (ClockSync, kwargs(window=arg(st.integers(1, 64))), ()),
        (
            clock.add,
            kwargs(
                host_send_s=arg(st.floats(0, 10)),
                host_recv_s=arg(st.floats(0, 10)),
                mcu_time_us=arg(st.integers(0, 2**32 - 1)),
            ),
            (),
        ),
        (clock.unwrap, kwargs(mcu_time_us=arg(st.integers(0, 2**32 - 1))), ()),
        (clock.offset_us, kwargs(host_s=arg(st.floats(0, 10))), ()),
        (clock.to_host_s, kwargs(mcu_us_unwrapped=arg(st.integers(0, 2**40))), ()),
        (get_profile, kwargs(name=arg(st.sampled_from(sorted(PROFILES)))), ()),
        (
            kinematics_for,
            kwargs(profile=arg(st.sampled_from(sorted(PROFILES))), config=arg(st.just(PROFILES["picar"].config))),
            (),
        ),
        (steering_limits, kwargs(config=arg(st.just(PROFILES["picar"].config))), ()),
        (steering_angles, kwargs(config=arg(st.just(PROFILES["picar"].config))), ()),
        (encode_frame, kwargs(msg=arg(valid_msg), seq=arg(st.integers(0, 255))), ()),
        (decoder.feed, kwargs(data=arg(st.binary(max_size=80))), ()),
        (FrameDecoder, kwargs(), ()),
        (
            lambda **kw: messages.SetWheelSpeeds(**kw).pack(),
            kwargs(left_mm_s=arg(st.integers(-500, 500)), right_mm_s=arg(st.integers(-500, 500))),
            (),
        ),
    ]


@settings(max_examples=500)
@given(data=st.data())
def test_junk_to_kinematics_odometry_timesync_profiles_and_codec(data: st.DataObject) -> None:
    function, args_strategy, allowed = data.draw(st.sampled_from(module_calls()), label="callable")
    passed = data.draw(args_strategy, label="arguments")
    outcome(lambda: function(**passed), passed, allowed)
