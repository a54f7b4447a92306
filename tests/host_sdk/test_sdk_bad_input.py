"""The bad inputs the hostile-tester report listed, one by one: each raises an SDK error naming
the argument (or says plainly what is wrong), instead of a crash from deep inside, a silently
accepted value or a silently wrong result."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest

from host_sdk import Ackermann, DiffDrive, Robot
from host_sdk.errors import ArgumentError, ArgumentTypeError, RobotClosedError, TransportError, UnsupportedError

URL = "emu://diffdrive-tb6612?clock=virtual"


class Opaque:
    """Any object that is none of the things asked for (a repr without an address, so the test
    ids are the same in every pytest-xdist worker)."""

    def __repr__(self) -> str:
        return "Opaque()"


CONNECT = [
    ({"url": None}, "url"),
    ({"request_timeout_s": 0}, "request_timeout_s"),
    ({"request_timeout_s": math.nan}, "request_timeout_s"),
    ({"request_timeout_s": None}, "request_timeout_s"),
    ({"request_tries": 0}, "request_tries"),
    ({"request_tries": -1}, "request_tries"),
    ({"kinematics": Opaque()}, "kinematics"),
    ({"kinematics": "diff"}, "kinematics"),
    ({"profile": 3}, "profile"),
    ({"profile": "tank"}, "profile"),
    ({"baud": True}, "baud"),
    ({"watchdog_s": 10}, "watchdog_s"),
    ({"clamp": "yes"}, "clamp"),
    ({"timeout_s": -1}, "timeout_s"),
]


@pytest.mark.parametrize(("kwargs", "argument"), CONNECT, ids=[repr(k) for k, _ in CONNECT])
def test_connect_refuses_bad_keywords_naming_them(kwargs: dict[str, Any], argument: str) -> None:
    url = kwargs.pop("url", URL)
    with pytest.raises(ArgumentError) as err:
        Robot.connect(url, **kwargs)
    assert err.value.argument == argument and argument in str(err.value)


ROBOT_CALLS: list[tuple[Callable[[Robot], Any], str]] = [
    (lambda r: r.arm(timeout_s=math.nan), "timeout_s"),
    (lambda r: r.wait_feedback(timeout_s=-1), "timeout_s"),
    (lambda r: r.wait_feedback(timeout_s=math.inf), "timeout_s"),
    (lambda r: r.on_feedback("print"), "callback"),
    (lambda r: r.drive(True, 0.0), "linear_m_s"),
    (lambda r: r.drive(0.1, 0.0, clamp=1), "clamp"),
    (lambda r: r.drive(0.1, 0.0, hold_s=-2), "hold_s"),
    (lambda r: r.sleep(-1), "seconds"),
    (lambda r: r.pid(wheel=2), "wheel"),
    (lambda r: r.set_pid(kp=math.nan), "kp"),
    (lambda r: r.set_config(max_wheel_speed_mm_s=2**64), "max_wheel_speed_mm_s"),
    (lambda r: r.odometry.reset(x_m=1e300), "x_m"),
    (lambda r: r.mcu_to_host_s("now"), "mcu_time_us"),
]


@pytest.mark.parametrize(("call", "argument"), ROBOT_CALLS, ids=[a for _, a in ROBOT_CALLS])
def test_robot_methods_refuse_bad_arguments_naming_them(
    roverlink_robot: Robot, call: Callable[[Robot], Any], argument: str
) -> None:
    roverlink_robot.arm()
    with pytest.raises(ArgumentError) as err:
        call(roverlink_robot)
    assert err.value.argument == argument


KINEMATICS: list[tuple[Callable[[], Any], str]] = [
    (lambda: DiffDrive(0.03, 0.2, 1560).wheel_speeds(math.nan, 0.0, 1.0), "linear_m_s"),
    (lambda: DiffDrive(True, 0.2, 1560), "wheel_radius_m"),  # type: ignore[arg-type]
    (lambda: DiffDrive(0.03, 1e300, 1560), "track_m"),
    (lambda: DiffDrive(0.03, 0.2, 2**64), "counts_per_rev"),
    (lambda: Ackermann(0.26, 0.03, 720, max_steering_rad=math.pi), "max_steering_rad"),
    (lambda: Ackermann(math.inf, 0.03, 720), "wheelbase_m"),
]


@pytest.mark.parametrize(("call", "argument"), KINEMATICS, ids=[a for _, a in KINEMATICS])
def test_kinematics_refuse_bad_arguments_naming_them(call: Callable[[], Any], argument: str) -> None:
    with pytest.raises(ArgumentError) as err:
        call()
    assert err.value.argument == argument


def test_wrong_types_are_also_type_errors() -> None:
    with pytest.raises(TypeError):
        DiffDrive("3 cm", 0.2, 1560)  # type: ignore[arg-type]
    assert issubclass(ArgumentTypeError, ArgumentError) and issubclass(ArgumentTypeError, ValueError)


def test_odometry_of_a_closed_robot_raises(roverlink_robot: Robot) -> None:
    assert roverlink_robot.odometry.pose is not None
    roverlink_robot.close()
    with pytest.raises(RobotClosedError):
        roverlink_robot.odometry.pose  # noqa: B018
    with pytest.raises(RobotClosedError):
        roverlink_robot.odometry.reset()


def test_capability_messages_name_the_kind_of_robot(roverlink_robot: Robot) -> None:
    roverlink_robot.arm()
    with pytest.raises(UnsupportedError) as err:
        roverlink_robot.drive_ackermann(0.2, 0.1)
    assert "needs an Ackermann (steered) robot" in str(err.value) and "a ACKERMANN" not in str(err.value)


def test_messages_say_what_is_wrong_in_the_users_terms() -> None:
    with pytest.raises(ArgumentError) as err:
        Robot.connect("emu://?bogus=1")
    assert err.value.argument == "url" and "'bogus' = '1'" in str(err.value)
    assert "'bogus' = 'emu://" not in str(err.value)  # the parameter's value, not the whole URL
    with pytest.raises(ArgumentError) as err:
        Robot.connect("emu://?seed=-1")
    assert "0..9223372036854775808" in str(err.value) and "e+18" not in str(err.value)
    with pytest.raises(TransportError, match="it is a file, not a serial port"):
        Robot.connect(__file__)


def test_numpy_scalars_are_numbers() -> None:
    np = pytest.importorskip("numpy")
    with Robot.connect(URL, watchdog_s=np.float32(0.5), feedback_hz=np.int64(50)) as robot:
        robot.arm(timeout_s=np.float64(2.0))
        robot.drive(np.float32(0.2), np.float16(0.0))
        robot.set_wheel_speeds(np.float32(0.2), np.int32(0))
        robot.sleep(np.float32(0.1))
        assert robot.pid(wheel=np.int8(0)) is not None


@pytest.mark.parametrize(
    "bad",
    [
        "numpy.bool_(True)",
        "numpy.complex128(0.2)",
        "numpy.float32('nan')",
        "numpy.float64('inf')",
        "complex(0.2, 0)",
        "'0.2'",
    ],
)
def test_numpy_scalars_that_are_no_finite_real_are_refused(bad: str) -> None:
    numpy = pytest.importorskip("numpy")
    value = eval(bad, {"numpy": numpy})
    with Robot.connect(URL) as robot, pytest.raises(ArgumentError) as err:
        robot.drive(value, 0.0)
    assert err.value.argument == "linear_m_s"
