"""A harness process stepped by request/reply lines over pipes (the simavr and rp2040 harnesses).

Each request is one line on the process's stdin, each reply one line on its stdout; a reply that
starts with ERR, or none (the process ended), raises the backend's error with what it said.
"""

from __future__ import annotations

import contextlib
import subprocess
from pathlib import Path


class PipeProcess:
    def __init__(self, cmd: list[str], cwd: Path, error: type[RuntimeError], name: str) -> None:
        self._error = error
        self._name = name
        # A session of its own: Ctrl-C in a terminal signals the whole foreground process group,
        # and the harness must outlive that signal so its owner can stop it in order (close()).
        self._proc = subprocess.Popen(
            cmd,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,  # stderr stays the owner's: a full pipe nobody reads would stall it
            text=True,
            bufsize=1,
            cwd=cwd,
            start_new_session=True,
        )
        while not self.readline().startswith("READY"):
            pass

    @property
    def pid(self) -> int:
        return self._proc.pid

    def readline(self) -> str:
        assert self._proc.stdout is not None
        line = self._proc.stdout.readline()
        if not line:
            raise self._error(f"the {self._name} exited (code {self._proc.wait()})")
        return line

    def ask(self, command: str) -> list[str]:
        """The reply to `command`, split into words."""
        assert self._proc.stdin is not None
        self._proc.stdin.write(command + "\n")
        self._proc.stdin.flush()
        reply = self.readline().split()
        if not reply or reply[0] == "ERR":
            raise self._error(f"the {self._name} refused {command!r}: {' '.join(reply[1:])}")
        return reply

    def close(self) -> None:
        """Asks the process to quit (Q), then waits for it, killing it after 5 s."""
        if self._proc.poll() is None:
            with contextlib.suppress(self._error, BrokenPipeError, OSError):
                self.ask("Q")
            try:
                self._proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        for stream in (self._proc.stdin, self._proc.stdout):
            if stream is not None:
                stream.close()
