"""`roverlink emulate` in a subprocess: the board (and any sensors) served on ptys, a TCP socket and
HTTP in real time, as a test would find real hardware.

    with emulate("--profile", "picar", "--quiet") as board:
        Robot.connect(board.url)

The serve command prints the board's port first (a pty path or a socket:// URL), then one line per
device ("lidar rplidar-a1 ... /dev/pts/7"); `devices=` says how many of those to wait for.
"""

from __future__ import annotations

import os
import select
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO

from tests.support.wait import Deadline

ROOM = Path(__file__).resolve().parents[2] / "examples" / "worlds" / "room.toml"
SENSOR_ROBOT_ARGS = (
    *("--profile", "diffdrive-bts7960", "--world", str(ROOM)),
    *("--lidar", "rplidar-a1", "--imu", "jy901", "--camera", "--quiet", "--seed", "3"),
)
"""`roverlink emulate`'s arguments for a robot in a room with a lidar, an IMU and a camera, each
served on a port of its own (the sensor suites' robot)."""
READY_TIMEOUT_S = 60.0  # a cold start imports cv2 and numpy on a busy machine
STOP_TIMEOUT_S = 10.0


class EmulatorProcess:
    """A running `python -m roverlink emulate ARGS`; ready (its port lines read) once constructed."""

    def __init__(
        self,
        *args: str,
        devices: int = 0,
        stderr: int | IO[str] | None = subprocess.DEVNULL,
        cwd: Path | None = None,
        timeout_s: float = READY_TIMEOUT_S,
    ) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "roverlink", "emulate", *args],
            stdout=subprocess.PIPE,
            stderr=stderr,
            text=True,
            cwd=cwd,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        try:
            self.lines = [_read_line(self.proc, Deadline(timeout_s)) for _ in range(1 + devices)]
        except BaseException:
            self.stop()
            raise

    @property
    def url(self) -> str:
        """The board's port: a pty path or a socket:// URL."""
        return self.lines[0]

    @property
    def devices(self) -> dict[str, list[str]]:
        """Each device's line split into words, by its first word ("lidar", "imu", "camera")."""
        return {line.split()[0]: line.split() for line in self.lines[1:]}

    def stop(self) -> int:
        """Terminates the process (killed if it does not stop) and returns its exit status."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for stream in (self.proc.stdout, self.proc.stderr):
            if stream is not None:
                stream.close()
        return self.proc.returncode


@contextmanager
def emulate(
    *args: str,
    devices: int = 0,
    stderr: int | IO[str] | None = subprocess.DEVNULL,
    cwd: Path | None = None,
    clean_exit: bool = False,
) -> Iterator[EmulatorProcess]:
    """An `EmulatorProcess` for the block; stopped after it (`clean_exit`: asserting exit status 0)."""
    served = EmulatorProcess(*args, devices=devices, stderr=stderr, cwd=cwd)
    try:
        yield served
    finally:
        status = served.stop()
    if clean_exit:
        assert status == 0, f"roverlink emulate exited with {status}"


def _read_line(proc: subprocess.Popen[str], deadline: Deadline) -> str:
    """One stripped line of the process's stdout, read byte by byte from the pipe so nothing past it
    is buffered away from later readers (`communicate()`)."""
    assert proc.stdout is not None
    fd = proc.stdout.fileno()
    line = bytearray()
    while not line.endswith(b"\n"):
        ready, _, _ = select.select([fd], [], [], deadline.remaining())
        if not ready:
            raise AssertionError(f"roverlink emulate printed no port line in time (so far {bytes(line)!r})")
        byte = os.read(fd, 1)
        if not byte:
            raise AssertionError(f"roverlink emulate exited ({proc.wait()}) before printing its port")
        line += byte
    return line.decode().strip()
