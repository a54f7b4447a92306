"""`roverlink console` as a user starts it, in its own process, watched through its WebSocket as the
page sees it; and `roverlink emulate`'s progress log, to time what the console shows against what
the emulator did.

    with emulate(..., stderr=subprocess.PIPE) as board:
        log = EmulatorLog(board)                 # "[emulator] t=30.000s fault: link cut" and when it came
        with ConsoleProcess("--url", board.url, ...) as console, console.page() as page:
            page.send(type="arm", on=True)
            page.wait(lambda s: s["armed"], 5, "armed")
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

from websockets.sync.client import ClientConnection, connect

from tests.support.emulate import EmulatorProcess
from tests.support.wait import wait_until

ROOT = Path(__file__).resolve().parents[3]
START_TIMEOUT_S = 90.0  # a cold start imports OpenCV, numpy and aiohttp on a busy machine
State = dict[str, Any]


def until(check: Callable[[], Any], timeout_s: float, what: str) -> Any:
    return wait_until(check, timeout_s, what, poll_s=0.02)


class Lines:
    """A text stream read on a thread of its own: each line with the monotonic time it arrived."""

    def __init__(self, stream: IO[str]) -> None:
        self.lines: list[tuple[float, str]] = []
        self._lock = threading.Lock()
        threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream: IO[str]) -> None:
        for line in stream:
            with self._lock:
                self.lines.append((time.monotonic(), line.rstrip("\n")))

    def find(self, pattern: str, after: float = 0.0) -> tuple[float, str] | None:
        """The first line matching `pattern` that arrived after `after`."""
        with self._lock:
            return next(((t, line) for t, line in self.lines if t > after and re.search(pattern, line)), None)

    def wait(self, pattern: str, timeout_s: float, after: float = 0.0) -> tuple[float, str]:
        found: tuple[float, str] = until(lambda: self.find(pattern, after), timeout_s, f"a line {pattern!r}")
        return found

    def text(self) -> str:
        with self._lock:
            return "\n".join(line for _, line in self.lines)


class EmulatorLog(Lines):
    """`roverlink emulate`'s progress log (started with stderr=PIPE and without --quiet)."""

    def __init__(self, board: EmulatorProcess) -> None:
        assert board.proc.stderr is not None, "start roverlink emulate with stderr=subprocess.PIPE"
        super().__init__(board.proc.stderr)


class ConsoleProcess:
    """`python -m roverlink console ARGS --port 0`, listening once constructed (`port`, `log`)."""

    def __init__(self, *args: str) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "roverlink", "console", *args, "--port", "0"],
            cwd=ROOT,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert self.proc.stderr is not None
        self.log = Lines(self.proc.stderr)
        try:
            _, line = until(
                lambda: self.log.find(r"open http://") or (self.proc.poll() is not None and ("", "")),
                START_TIMEOUT_S,
                "the console's URL",
            )
            found = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
            assert found, f"the console did not start:\n{self.log.text()}"
            self.port = int(found.group(1))
        except BaseException:
            self.stop()
            raise

    @property
    def alive(self) -> bool:
        return self.proc.poll() is None

    @contextmanager
    def page(self) -> Iterator[Page]:
        origin = f"http://127.0.0.1:{self.port}"
        with connect(f"ws://127.0.0.1:{self.port}/ws", origin=origin, open_timeout=10) as ws:  # type: ignore[arg-type]
            yield Page(ws)

    def stop(self) -> int:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        return self.proc.returncode

    def __enter__(self) -> ConsoleProcess:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


class Page:
    """What a page is sent (the state merged as the page merges it), on a thread; `send` what it
    sends, and its keep-alive every third of the command lifetime while `alive` is set, as a page does."""

    def __init__(self, ws: ClientConnection) -> None:
        self.ws = ws
        self.state: State = {}
        self.history: list[tuple[float, State]] = []
        self.messages: list[State] = []
        self.alive = threading.Event()
        self.alive.set()
        self._every_s = 0.08
        self._lock = threading.Lock()
        threading.Thread(target=self._read, daemon=True).start()
        threading.Thread(target=self._keep_alive, daemon=True).start()

    def _keep_alive(self) -> None:
        try:
            while True:
                if self.alive.is_set():
                    self.send(type="alive")
                time.sleep(self._every_s * 0.8)  # a page's timer: no test waits on it
        except Exception:  # the socket closed: the keep-alive ends
            return

    def _read(self) -> None:
        try:
            while True:
                raw = self.ws.recv()
                if not isinstance(raw, str):
                    continue  # a camera frame
                msg = json.loads(raw)
                if msg["type"] == "hello":
                    self._every_s = msg["keepalive_s"]
                with self._lock:
                    self.messages.append(msg)
                    if msg["type"] == "state":
                        self.state = {**self.state, **msg}
                        self.history.append((time.monotonic(), self.state))
        except Exception:  # the socket closed: the reader ends
            return

    def send(self, **msg: Any) -> None:
        self.ws.send(json.dumps(msg))

    def now(self) -> State:
        with self._lock:
            return self.state

    def wait(self, check: Callable[[State], Any], timeout_s: float, what: str) -> State:
        """The first state (from now on) for which `check` holds; its arrival time is `at(state)`."""
        start = time.monotonic()

        def found() -> State | None:
            with self._lock:
                return next((s for t, s in self.history if t >= start and _holds(check, s)), None)

        try:
            state: State = until(found, timeout_s, what)
        except AssertionError as exc:
            shown = {k: v for k, v in self.now().items() if k not in ("scan", "pose", "motion")}
            raise AssertionError(f"{exc}; the page was last shown {shown}") from None
        return state

    def first(self, check: Callable[[State], Any], after: float) -> tuple[float, State] | None:
        """The first state that arrived after `after` for which `check` holds, and when."""
        with self._lock:
            return next(((t, s) for t, s in self.history if t > after and _holds(check, s)), None)

    def all_since(self, after: float, until_t: float) -> list[State]:
        with self._lock:
            return [s for t, s in self.history if after < t < until_t]


def _holds(check: Callable[[State], Any], state: State) -> bool:
    try:
        return bool(check(state))
    except (KeyError, TypeError):
        return False


def link(state: State) -> str:
    return str(state["link"]["state"])
