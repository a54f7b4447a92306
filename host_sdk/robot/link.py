"""`Link`: what every part of a `Robot` works through, owned once.

The transport (bytes), the sans-I/O session over it, the runner that drives the session (an I/O
thread, or inline on the emulator's virtual clock), the callbacks the runner dispatches, and the
lock that guards the session. The parts (driving, feedback, settings, odometry) keep their own
state and reach the board only through this.
"""

from __future__ import annotations

from host_sdk.errors import RobotClosedError
from host_sdk.robot.callbacks import Callbacks
from host_sdk.robot.runner import runner_for
from host_sdk.session import RobotConfig, RobotIdentity, Session, SessionOptions
from host_sdk.transport import Transport
from protocol.codec.message import Message


class Link:
    def __init__(self, transport: Transport, options: SessionOptions) -> None:
        self.transport = transport
        self.options = options
        self.session = Session(options)
        self.callbacks = Callbacks()
        self.runner = runner_for(self.session, transport, self.callbacks.dispatch)
        self.lock = self.runner.lock
        self.last_command_seq: int | None = None
        """The seq of the latest drive command sent: the FEEDBACK a lockstep board owes answers it."""

    @property
    def url(self) -> str:
        return self.transport.url

    @property
    def closed(self) -> bool:
        return self.runner.closed

    def clock(self) -> float:
        return self.transport.clock()

    def check_open(self) -> None:
        if self.runner.closed:
            raise RobotClosedError(self.url)

    def request(self, msg: Message) -> Message:
        """Send `msg` reliably and return the board's answer (raises what the runner raises)."""
        return self.runner.request(msg)

    def identity(self) -> RobotIdentity:
        """The current session's identity (raises RobotClosedError once closed)."""
        with self.lock:
            self.check_open()
            identity = self.session.identity
            assert identity is not None
            return identity

    def config(self) -> RobotConfig:
        """The board's configuration as last read or written."""
        with self.lock:
            self.check_open()
            config = self.session.config
            assert config is not None
            return config
