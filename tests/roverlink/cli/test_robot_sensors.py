"""One way to say which sensors a robot has, for every command (roverlink.sensors.sensors_for):
an option names a device; else the emu:// URL's own; else, on a real port, the robot file's
`[sensors.*]` port, camera source and IMU baud. `roverlink console` and `roverlink follow` take
an emu:// URL with its sensors as they take a robot, and a robot file's lidar port."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from host_sdk import Robot, RobotDescription, RoverLinkError
from protocol.robotfile import reference_path
from roverlink.cli import build_parser, main
from roverlink.follow.app import RobotPorts
from roverlink.interactive import URL_HELP, take_url
from roverlink.sensors import choose_sensors

SENSORS = "emu://picar?world=random:3&camera=320x240&lidar=ydlidar-f4"


def _file(tmp_path: Path) -> RobotDescription:
    """The PiCar with its lidar on a port, its camera's source and an IMU at 9600 baud."""
    text = reference_path("picar").read_text(encoding="utf-8")
    lidar, camera = 'model = "ydlidar-f4"', 'model = "pi-camera-v2"'
    assert text.count(lidar) == 1 and text.count(camera) == 1
    text = text.replace(lidar, f'{lidar}\nport = "/dev/serial/by-id/usb-lidar"')
    text = text.replace(camera, f'{camera}\nsource = "picamera2"')
    text += '\n[sensors.imu]\nmodel = "jy901"\nport = "/dev/ttyUSB1"\nbaud = 9600\n'
    path = tmp_path / "mine.toml"
    path.write_text(text, encoding="utf-8")
    return RobotDescription.load(path)


def _real(url: str = "/dev/ttyACM0") -> Any:
    """A connected robot on a real port, as sensors_for sees it."""
    return SimpleNamespace(url=url, transport=SimpleNamespace(endpoints={}, profile="picar"))


def test_a_real_robot_uses_the_robot_files_ports_camera_and_imu_baud(tmp_path: Path) -> None:
    desc = _file(tmp_path)
    ports = RobotPorts("/dev/ttyACM0", None, None)
    devices = ports.devices(_real(), desc)
    assert (devices.lidar, devices.lidar_model) == ("/dev/serial/by-id/usb-lidar", "ydlidar-f4")
    assert (devices.camera, devices.imu, devices.imu_baud) == ("picamera2", "/dev/ttyUSB1", 9600)
    # An option wins over the file.
    given = RobotPorts("/dev/ttyACM0", "/dev/ttyUSB0", "0", imu_baud=115200).devices(_real(), desc)
    assert (given.lidar, given.camera, given.imu_baud) == ("/dev/ttyUSB0", 0, 115200)


def test_the_record_commands_options_fall_back_to_the_robot_file(tmp_path: Path) -> None:
    desc = _file(tmp_path)
    args = build_parser().parse_args(["record", "/dev/ttyACM0", "-o", "x.mcap", "--robot", str(desc.path)])
    choice = choose_sensors(args, _real())
    assert (choice.lidar, choice.camera, choice.imu, choice.imu_baud) == (
        "/dev/serial/by-id/usb-lidar",
        "picamera2",
        "/dev/ttyUSB1",
        9600,
    )
    # An emulated robot's own devices are the emulator's, never the file's real ports.
    assert choose_sensors(args, _real("emu://picar")).lidar is None


def test_a_robot_without_a_lidar_says_the_three_ways_to_give_one() -> None:
    with pytest.raises(RoverLinkError) as error:
        RobotPorts("/dev/ttyACM0", None, "picamera2").devices(_real(), "picar")
    assert str(error.value) == (
        "no lidar for this robot: give --lidar PORT, [sensors.lidar] port in the --robot FILE, or lidar= in an "
        "emu:// URL"
    )


def test_an_emu_url_brings_its_own_lidar_and_camera() -> None:
    with Robot.connect(SENSORS + "&clock=virtual", profile="picar") as robot:
        devices = RobotPorts(robot.url, None, None).devices(robot, "picar")
        endpoints = robot.transport.endpoints
        assert (devices.lidar, devices.camera) == (endpoints["lidar"], endpoints["camera"])
        assert devices.lidar_model == "ydlidar-f4"


@pytest.mark.parametrize("command", ["console", "follow"])
def test_console_and_follow_take_the_same_sensor_options_as_record(command: str) -> None:
    args = build_parser().parse_args(
        [command, "--url", SENSORS, "--lidar", "/dev/ttyUSB0", "--imu", "/dev/ttyUSB1", "--imu-baud", "9600"]
    )
    assert (args.lidar, args.imu, args.imu_baud, args.camera) == ("/dev/ttyUSB0", "/dev/ttyUSB1", 9600, None)


def test_the_console_runs_on_an_emu_url_with_its_sensors(capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("aiohttp")
    assert main(["console", "--url", SENSORS, "--duration", "0.5", "--port", "0"]) == 0
    assert "roverlink console: open http://127.0.0.1:" in capsys.readouterr().err


DRIVING = ["info", "monitor", "teleop", "calibrate", "tune", "record", "console", "follow", "demo", "ros2"]
"""Every command that drives (or reads) a robot."""


@pytest.mark.parametrize("command", DRIVING)
def test_every_robot_command_takes_url_as_an_option(command: str) -> None:
    extra = ["-o", "run.mcap"] if command == "record" else []
    args = build_parser().parse_args([command, "--url", "/dev/ttyACM0", *extra])
    assert take_url(args) is None and args.url == "/dev/ttyACM0"
    # The URL and the line speed come from one place (interactive.add_url_args): the same help and
    # the same check of the baud rate in every command.
    sub = next(a for a in build_parser()._actions if a.dest == "command").choices[command]  # type: ignore[index]
    url = next(a for a in sub._actions if "--url" in a.option_strings or a.dest == "url")
    assert url.help is not None and url.help.startswith(URL_HELP.split(",")[0])
    with pytest.raises(SystemExit):
        build_parser().parse_args([command, "--url", "/dev/ttyACM0", "--baud", "0", *extra])


@pytest.mark.parametrize("command", ["console", "follow", "info"])
def test_the_url_is_the_first_argument_or_an_option_in_every_command_that_takes_one_first(command: str) -> None:
    args = build_parser().parse_args([command, "emu://picar"])
    assert take_url(args) is None and args.url == "emu://picar"


def test_the_url_as_an_option_connects_and_given_twice_or_not_at_all_is_refused(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["info", "--url", "emu://picar?clock=virtual"]) == 0
    assert "AckermannPiCar firmware" in capsys.readouterr().out
    assert main(["info", "emu://picar", "--url", "emu://picar"]) == 2
    assert capsys.readouterr().err.startswith("roverlink info: error: the URL given twice")
    assert main(["info"]) == 2
    assert "roverlink info: error: give the board's URL (first argument or --url)" in capsys.readouterr().err


def test_before_connecting_a_real_port_needs_the_lidar_and_camera_from_options_or_the_file(tmp_path: Path) -> None:
    RobotPorts("/dev/ttyACM0", None, None).check(_file(tmp_path))  # the file's lidar port and camera source
    RobotPorts("/dev/ttyACM0", "/dev/ttyUSB0", "0").check("picar")
    RobotPorts(SENSORS, None, None).check("picar")  # an emu:// URL's are known once connected
    with pytest.raises(RoverLinkError, match="no camera for this robot"):
        RobotPorts("/dev/ttyACM0", "/dev/ttyUSB0", None).check("picar")


def test_a_device_from_the_robot_file_that_will_not_open_names_the_files_key(tmp_path: Path) -> None:
    from host_sdk.sensors.errors import SensorOpenError
    from roverlink.sensors import open_imu, open_lidar

    desc = _file(tmp_path)
    choice = RobotPorts("/dev/ttyACM0", None, None).devices(_real(), desc)
    with pytest.raises(SensorOpenError) as lidar:
        open_lidar(choice)
    assert str(lidar.value).startswith("lidar ydlidar-f4 on /dev/serial/by-id/usb-lidar: could not open ")
    assert str(lidar.value).endswith(f"(from [sensors.lidar] port in {desc.path})") and lidar.value.kind == "lidar"
    with pytest.raises(SensorOpenError) as imu:
        open_imu(choice)
    assert str(imu.value).startswith("imu jy901 on /dev/ttyUSB1 at 9600 baud: could not open ")
    assert str(imu.value).endswith(f"(from [sensors.imu] port in {desc.path})")
    # A port given on the command line is the user's own: no file to point at.
    given = RobotPorts("/dev/ttyACM0", "/dev/nonexistent-lidar", None).devices(_real(), desc)
    with pytest.raises(SensorOpenError) as option:
        open_lidar(given)
    assert "from [sensors" not in str(option.value) and "/dev/nonexistent-lidar" in str(option.value)


def test_an_in_process_emulator_on_the_wall_clock_gets_the_longer_watchdog() -> None:
    from roverlink.follow.emulated import SHARED_WATCHDOG_S, watchdog_for

    assert watchdog_for(None, None) == watchdog_for(SENSORS, None) == SHARED_WATCHDOG_S == 1.0
    assert watchdog_for(SENSORS + "&clock=virtual", None) == watchdog_for("/dev/ttyACM0", None) == 0.25
    assert watchdog_for(SENSORS, 0.5) == 0.5  # --watchdog wins
    with Robot.connect(SENSORS, profile="picar", watchdog_s=watchdog_for(SENSORS, None)) as robot:
        assert robot.watchdog_s == 1.0  # granted by the emulated firmware


def test_roverlink_ros2_takes_the_sensor_options_as_the_parameters_they_set() -> None:
    from roverlink.commands.ros2 import overrides
    from roverlink.ros2.params import BY_NAME

    args = build_parser().parse_args(
        [
            "ros2",
            "--url",
            "/dev/ttyACM0",
            "--baud",
            "230400",
            "--lidar",
            "/dev/ttyUSB0",
            "--lidar-model",
            "ydlidar-f4",
            "--imu",
            "/dev/ttyUSB1",
            "--imu-baud",
            "9600",
        ]
    )
    got = overrides(args)
    assert got == {
        "url": "/dev/ttyACM0",
        "baud": 230400,
        "lidar_url": "/dev/ttyUSB0",
        "lidar_model": "ydlidar-f4",
        "imu_url": "/dev/ttyUSB1",
        "imu_baud": 9600,
    }
    assert set(got) <= set(BY_NAME)  # each one a parameter the node declares
    assert overrides(build_parser().parse_args(["ros2"])) == {}  # nothing given: the parameters decide


def test_an_emu_url_without_the_sensors_a_command_needs_is_told_the_url_with_them() -> None:
    from roverlink.sensors.options import SensorChoice, require_sensors

    with pytest.raises(RoverLinkError) as caught:
        require_sensors(SensorChoice(), ("lidar", "camera"), "emu://picar?clock=virtual")
    assert "(here: 'emu://picar?clock=virtual&lidar=ydlidar-f4&camera=320x240', or no URL" in str(caught.value)


@pytest.mark.parametrize(
    ("argv", "robot"),
    [
        (["follow", "emu://diffdrive-bts7960?clock=virtual"], "diffdrive-bts7960"),  # the URL's robot
        (["console", "--url", "emu://diffdrive-tb6612"], "diffdrive-tb6612"),
        (["follow", "emu://diffdrive-bts7960", "--profile", "picar"], "picar"),  # said outright
        (["console", "/dev/ttyACM0"], "picar"),  # a real port: the default
    ],
)
def test_console_and_follow_drive_the_robot_an_emu_url_names(argv: list[str], robot: str) -> None:
    from roverlink.interactive import robot_named

    args = build_parser().parse_args(argv)
    assert take_url(args) is None and robot_named(args, "picar") == robot
