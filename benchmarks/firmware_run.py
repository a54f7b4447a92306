"""The host's side of a firmware measurement (benchmarks/firmware.py): a session opened on the
example running in simavr, then each step of the method (idle polls, driving, the floods of
setpoint and SET_PID frames, the baseline), with what the harness counted in each."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from avr_sources import CLONE, symbol, symbols

from emulator.backends.simavr import Harness, SimavrRobot
from host_sdk import messages
from host_sdk.framing import Frame, FrameDecoder, encode_frame
from protocol.codec.message import Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.enums import FeedbackMode, IdentityReason
from protocol.generated.profiles import PROFILES

POLL_SYMBOL = "roverlink::Session<roverlink::Firmware>::poll()"
# Where decoding and dispatching end: the App's code (the handlers: SET_PID's gains applied, a
# setpoint stored, the session's actions on the motors) and sending a reply (packing and framing an
# ACK/NACK or an answer). Their cycles inside poll() are reported apart, as handling.
HANDLER_SYMBOLS = re.compile(
    r"^(roverlink::Firmware::\w+|roverlink::SessionCore::send_answer|roverlink::Link::send_payload)\("
)


LoopStats = tuple[int, int, int, int]
"""The harness's main-loop figures since the last read: passes, cycles, shortest and longest pass."""


@dataclass
class Profile:
    calls: int
    cycles: int
    cheapest_call: int
    longest_work: int
    """The longest call less the cycles of its handlers (and their replies)."""
    per_pc: dict[int, int]


class HostLink:
    """The host's end of the simulated serial line: frames sent with a running seq, and the frames
    the firmware sent while simulated time advanced."""

    def __init__(self, robot: SimavrRobot) -> None:
        self.robot = robot
        self.decoder = FrameDecoder()
        self.frames: list[Frame] = []
        self.seq = 0

    def run(self, ms: int) -> None:
        self.robot.advance_us(ms * 1000)
        self.frames.extend(e for e in self.decoder.feed(self.robot.host_read()) if isinstance(e, Frame))

    def send(self, msg: Message) -> None:
        self.robot.host_write(encode_frame(msg, self.seq))
        self.seq = (self.seq + 1) & 0xFF


@dataclass
class Flood:
    """Frames of one kind sent back to back for 1 s, and what the harness counted meanwhile."""

    frames: int
    frame_bytes: int
    loop: LoopStats
    profile: Profile
    longest_call: int


@dataclass
class Run:
    """What the harness counted in each step of a measurement."""

    idle: Profile
    driving: LoopStats
    ticks: int
    setpoints: Flood
    set_pids: Flood
    rx: tuple[int, int, int]
    """The longest RX interrupt latency, the bytes received and the overruns, over the SET_PID flood."""
    base: LoopStats
    sim_s: float


def exercise(robot: SimavrRobot, elf: Path, example: str, profile: str) -> Run:
    """Open a session, then: idle polls, driving, a setpoint flood, a SET_PID flood, driving again
    (the baseline of ticks and FEEDBACK)."""
    h = robot.harness
    link = HostLink(robot)
    _open_session(link, profile)
    _start_profiling(h, elf)
    # 0. No host bytes: every poll() call finds nothing.
    link.run(20)
    idle = Profile(*h.profile())
    h.loop_stats()
    # 1. Driving: one setpoint per tick, FEEDBACK streaming.
    ticks = 200
    driving = _drive(link, profile, ticks)
    h.profile()
    h.rx_stats()
    # 2. Setpoint frames back to back for 1 s (the line's capacity).
    setpoints = _flood(link, setpoint(profile, 200))
    # 3. SET_PID frames back to back for 1 s (each answered by an ACK).
    set_pids = _flood(link, messages.SetPid(255, 1.0, 6.0, 0.0, 1.5, 0.0))
    acks = sum(isinstance(f.message, messages.Ack) and f.message.req_id == messages.SetPid.MSG_ID for f in link.frames)
    if acks != set_pids.frames:
        raise SystemExit(f"BENCHMARK INVALID: {example}: {acks} ACKs to {set_pids.frames} SET_PID frames")
    rx = h.rx_stats()
    # 4. Idle baseline with the session open (ticks and FEEDBACK only) for the per-ms rate.
    base = _drive(link, profile, 100)
    return Run(idle, driving, ticks, setpoints, set_pids, rx, base, robot.now_us / 1e6)


def _open_session(link: HostLink, profile: str) -> None:
    """From boot to armed: HELLO in STREAM mode, the ESC's arming setpoints where it has some, ARM."""
    link.run(300)
    boot = next(f.message for f in link.frames if isinstance(f.message, messages.Identity))
    assert isinstance(boot, messages.Identity) and boot.reason == IdentityReason.BOOT
    link.send(messages.Hello(PROTOCOL_VERSION, SPEC_HASH, 0, FeedbackMode.STREAM, 0))
    link.run(20)
    if PROFILES[profile].config.esc_arm_ms:
        for _ in range(PROFILES[profile].config.esc_arm_ms // 10):
            link.send(setpoint(profile, 0))
            link.run(10)
    link.send(messages.Arm(boot.boot_id))
    link.run(20)


def _start_profiling(h: Harness, elf: Path) -> None:
    """Mark the main loop's passes, profile poll() and keep its handlers' cycles apart."""
    h.set_loop_marker(symbol(elf, "serialEventRun()"))
    h.profile_function(symbol(elf, POLL_SYMBOL))
    for address, name in symbols(elf):
        if HANDLER_SYMBOLS.match(CLONE.sub("", name)):
            h.profile_handler(address)


def _drive(link: HostLink, profile: str, ticks: int) -> LoopStats:
    """One setpoint per control tick: the main loop's figures over those ticks."""
    for _ in range(ticks):
        link.send(setpoint(profile, 200))
        link.run(10)
    return link.robot.harness.loop_stats()


def _flood(link: HostLink, msg: Message) -> Flood:
    """As many frames of `msg` as the line carries in 1 s, sent at once; the frames received before
    are dropped, so what the firmware answered to the flood can be counted."""
    h = link.robot.harness
    frame_bytes = len(encode_frame(msg, 0))
    n = 115_200 // 10 // frame_bytes
    link.frames.clear()
    for _ in range(n):
        link.send(msg)
    link.run(1010)
    loop = h.loop_stats()
    return Flood(n, frame_bytes, loop, Profile(*h.profile()), h.longest_call())


def setpoint(profile: str, speed: int) -> Message:
    if str(PROFILES[profile].kinematics) == "ackermann":
        return messages.SetAckermann(speed, 0)
    return messages.SetWheelSpeeds(speed, speed)
