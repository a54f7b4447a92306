"""`roverlink emulate`'s progress log names every boot and its boot_id, on both backends: the
power-on boot and the one after the DTR reset a host causes by opening the port. The serve loops
run on wall time; each test waits for its condition with a deadline."""

from __future__ import annotations

import io
import re
from collections.abc import Callable

import pytest

from emulator.device import Emulator
from emulator.transport.realtime import serve as serve_python
from tests.support.simavr import simavr_robot
from tests.support.wait import Deadline

DEADLINE_S = 30.0
BOOT_LINE = re.compile(r"boot, boot_id 0x([0-9A-F]{8})")


class ScriptedEndpoint:
    """A host that opens the port once `connect_when()` holds, then stays silent."""

    name = "scripted"

    def __init__(self, connect_when: Callable[[], bool]) -> None:
        self.connect_when = connect_when
        self.connected = False
        self.written = b""

    def poll(self) -> tuple[bool, int]:
        if not self.connected and self.connect_when():
            self.connected = True
            return True, 1
        return self.connected, 0

    def on_connect(self) -> None:
        pass

    def read(self) -> bytes:
        return b""

    def write(self, data: bytes) -> None:
        self.written += data

    def wait(self, timeout_s: float) -> None:
        pass

    def close(self) -> None:
        pass


def logged_boots(run: Callable[[ScriptedEndpoint, io.StringIO, Callable[[], bool]], object]) -> list[int]:
    """Serves until two boots are logged: power-on, then the DTR reset of a host that opens the
    port after the first one."""
    log = io.StringIO()
    deadline = Deadline(DEADLINE_S)

    def boots() -> list[int]:
        return [int(h, 16) for h in BOOT_LINE.findall(log.getvalue())]

    def stop() -> bool:
        return len(boots()) >= 2 or deadline.expired()

    run(ScriptedEndpoint(lambda: len(boots()) >= 1), log, stop)
    return boots()


def test_python_emulator_logs_each_boot_id() -> None:
    emu = Emulator("diffdrive-tb6612", seed=4)
    boots = logged_boots(lambda endpoint, log, stop: serve_python(emu, endpoint, stop, log=log))
    assert boots == list(emu.truth.mcu.boot_ids) and len(boots) == 2 and boots[0] != boots[1]


def test_simavr_backend_logs_each_boot_id() -> None:
    simavr = pytest.importorskip("emulator.backends.simavr")
    try:
        robot = simavr_robot("picar", seed=4, bootloader_ms=100)
    except simavr.SimavrError as exc:  # pragma: no cover
        pytest.fail(f"the simavr backend needs avr-gcc, the Arduino core and simavr (scripts/test.sh): {exc}")
    with robot:
        boots = logged_boots(lambda endpoint, log, stop: serve_python(robot, endpoint, stop, log=log, tag="simavr"))
        assert boots == list(robot.truth.boot_ids) and len(boots) == 2 and boots[0] != boots[1]
