"""An emulated robot for one test, from the options the pytest plugin's marker takes.

`emulated_robot(**options)` is what the plugin's `robot` fixture is built from, as a context
manager: use it where a fixture cannot go, e.g. inside a Hypothesis ``@given`` test, whose body
runs once per example while a function-scoped fixture would be shared by all of them (Hypothesis
refuses that: the ``function_scoped_fixture`` health check). Every example gets a fresh robot::

    @given(steps=command_sequences("diffdrive-tb6612"))
    def test_odometry_follows_the_truth(steps: list[Step]) -> None:
        with emulated_robot(armed=True) as robot:
            run_steps(robot, steps)
            ...

The options (all optional; `OPTIONS` lists them):

- the emulator: `profile`, `seed`, `faults`, `eeprom`, and the sensors `world`, `lidar`,
  `lidar_hz`, `imu`, `camera`: the ``emu://`` URL's query parameters of the same names
  (emulator.transport.inprocess; their URLs are then in `robot.transport.endpoints`);
- `armed`: arm before handing the robot over;
- anything `Robot.connect` takes by keyword: `mode`, `watchdog_s`, `clamp`, `auto_rearm`, ...

    >>> with emulated_robot(profile="picar", imu="jy901", armed=True) as robot:
    ...     sorted(robot.transport.endpoints), robot.armed
    (['imu'], True)
"""

from __future__ import annotations

import contextlib
import inspect
from collections.abc import Iterator, Mapping
from typing import Any
from urllib.parse import quote

from host_sdk.robot import Robot

__all__ = ["DEFAULTS", "OPTIONS", "SENSOR_OPTIONS", "check_options", "emulated_robot", "emulator_url"]

DEFAULTS: dict[str, Any] = {"profile": "diffdrive-tb6612", "seed": 0, "faults": "", "armed": False, "eeprom": "saved"}
SENSOR_OPTIONS = ("world", "lidar", "lidar_hz", "imu", "camera")
"""Options that attach a sensor (or a world) to the emulator: URL query parameters."""
_CONNECT_OPTIONS = tuple(
    name
    for name, p in inspect.signature(Robot.connect).parameters.items()
    if p.kind is p.KEYWORD_ONLY and name != "transport"  # the transport is the emulator's
)
OPTIONS = tuple(dict.fromkeys((*DEFAULTS, *SENSOR_OPTIONS, *_CONNECT_OPTIONS)))
"""Every option `emulated_robot` and the `roverlink` marker accept."""


def check_options(options: Mapping[str, object], where: str = "emulated_robot") -> None:
    """TypeError naming each option `where` does not know, and listing the ones it does."""
    unknown = [key for key in options if key not in OPTIONS]
    if unknown:
        names = ", ".join(repr(k) for k in unknown)
        raise TypeError(f"{where}: unknown option {names}; the options are: {', '.join(OPTIONS)}")


def _query_value(value: object) -> str:
    if value is True:  # camera=True: the default camera
        return "1"
    return quote(str(value), safe="/:,")


def emulator_url(profile: str, seed: int = 0, faults: str = "", eeprom: str = "saved", **sensors: object) -> str:
    """The emu:// URL of a virtual-clock emulator; `sensors` are `SENSOR_OPTIONS` (None or False: none).

    >>> emulator_url("picar", seed=3, imu="jy901")
    'emu://picar?seed=3&clock=virtual&eeprom=saved&imu=jy901'
    """
    check_options({key: None for key in sensors if key not in SENSOR_OPTIONS}, "emulator_url")
    url = f"emu://{profile}?seed={seed}&clock=virtual&eeprom={eeprom}"
    if faults:
        url += "&faults=" + quote(faults, safe=",")
    for key in SENSOR_OPTIONS:  # a fixed order: the same options, the same URL
        value = sensors.get(key)
        if value is not None and value is not False:
            url += f"&{key}={_query_value(value)}"
    return url


@contextlib.contextmanager
def emulated_robot(**options: Any) -> Iterator[Robot]:
    """A Robot on a fresh in-process emulator with a virtual clock, connected (and armed with
    `armed=True`); closed when the block ends. `options` update `DEFAULTS` (see the module)."""
    check_options(options)
    merged = {**DEFAULTS, **options}
    url_options = {key: merged.pop(key) for key in (*DEFAULTS, *SENSOR_OPTIONS) if key in merged and key != "armed"}
    armed = merged.pop("armed")
    profile = url_options.pop("profile")
    bot = Robot.connect(emulator_url(profile, **url_options), profile=profile, **merged)
    try:
        if armed:
            bot.arm()
        yield bot
    finally:
        bot.close()
