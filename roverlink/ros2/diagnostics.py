"""What the node reports on /diagnostics, as plain values (the node turns them into DiagnosticStatus).

Two statuses per node, as rqt_robot_monitor and diagnostic_aggregator expect:

- `<node>: link`: the connection, both sides' link counters with rates, RTT and clock sync.
  ERROR while there is no connection (reconnecting), WARN when an error counter rose since the
  last report or the host sent paced lockstep setpoints late (`paced_late`), else OK.
- `<node>: robot`: the firmware's identity and the robot's state. ERROR in FAILSAFE (with the
  reason), WARN while a board reset has left it disarmed or the session is re-opening, or while
  the board differs from the robot file (allowed with allow_mismatch: each difference named), else OK.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field

from host_sdk import LinkStatistics, RobotIdentity
from host_sdk.failsafe import failsafe_meaning
from protocol.generated.enums import FailsafeReason
from protocol.generated.messages import LinkStats
from protocol.generated.structs import DecoderCountersSnapshot

OK, WARN, ERROR, STALE = 0, 1, 2, 3
"""diagnostic_msgs/DiagnosticStatus levels."""

# The error counters, by the spec's counter sets: the decoder's (both sides keep them) but its
# good frames, and seq gaps; the board also counts bytes its full receive buffer lost.
_DECODER_ERRORS = tuple(f.name for f in dataclasses.fields(DecoderCountersSnapshot) if f.name != "frames_ok")
HOST_ERRORS = (*_DECODER_ERRORS, "seq_gaps")
BOARD_ERRORS = (*HOST_ERRORS, "rx_overruns")
HOST_LATE = ("paced_late",)
"""The host's own lateness: not the link's errors, but lockstep periods lost the same way."""


def feedback_expected_s(state: str, lockstep: bool, commanding: bool, odom_rate: float) -> float | None:
    """How often FEEDBACK must arrive now (None: none is due). An open session streams it, a
    lockstep one too while it is not armed; an armed lockstep robot answers commands only, so it is
    due then only while the node commands it. Re-opening after a reset: the board is booting."""
    if state == "connecting" or (lockstep and state == "armed" and not commanding):
        return None
    return max(0.5, 5.0 / odom_rate)


@dataclass(frozen=True, slots=True)
class Event:
    """Something the node saw happen: a board reset, a failsafe, a lost or re-made connection."""

    time_s: float
    """Host clock (time.monotonic)."""
    kind: str
    text: str


@dataclass(frozen=True, slots=True)
class Report:
    level: int
    name: str
    message: str
    hardware_id: str
    values: tuple[tuple[str, str], ...] = field(default_factory=tuple)


@dataclass(frozen=True, slots=True)
class Snapshot:
    """Everything one report is made of, taken at `time_s` (host clock)."""

    time_s: float
    url: str
    connection: str
    """connecting, connected, reconnecting or failed."""
    connection_error: str = ""
    attempts: int = 0
    """Failed connection attempts since the last success."""
    reconnects: int = 0
    mode: str = ""
    identity: RobotIdentity | None = None
    state: str = ""
    """The robot's state: connecting, disarmed, armed, failsafe (Robot.state)."""
    failsafe: FailsafeReason | None = None
    host: LinkStatistics | None = None
    board: LinkStats | None = None
    board_time_s: float | None = None
    last_reset: Event | None = None
    resets: int = 0
    failsafes: int = 0
    last_failsafe: Event | None = None
    rearmed_since_reset: bool = True
    feedback_hz: float | None = None
    feedback_age_s: float | None = None
    """Seconds since the last FEEDBACK (None before the first)."""
    feedback_expected_s: float | None = None
    """FEEDBACK should arrive at least this often now (None: none is due, e.g. while re-opening)."""
    refused: int = 0
    last_refusal: str = ""
    tf: str = ""
    """What happens to /tf: published, off, or why it is not published."""
    mismatches: tuple[str, ...] = ()
    """How the board differs from the robot file, allowed with allow_mismatch (host_sdk Mismatch)."""
    extra: tuple[Report, ...] = ()
    """Reports of the sensors (lidar, imu), added as they are."""


def _errors(counters: object, names: Sequence[str]) -> dict[str, int]:
    return {name: int(getattr(counters, name)) for name in names}


def _rate(now: int, before: int | None, dt: float | None) -> str:
    if before is None or dt is None or dt <= 0 or now < before:
        return "-"
    return f"{(now - before) / dt:.1f}"


def _ago(event: Event | None, now: float) -> str:
    return "never" if event is None else f"{event.text} ({now - event.time_s:.1f} s ago)"


class DiagnosticsBuilder:
    """Turns snapshots into reports; keeps the previous snapshot for rates and rising error counts."""

    def __init__(self, node_name: str) -> None:
        self.node_name = node_name
        self._prev: Snapshot | None = None

    def build(self, snap: Snapshot) -> list[Report]:
        prev, self._prev = self._prev, snap
        return [self._link(snap, prev), self._robot(snap), *snap.extra]

    def _rising(self, snap: Snapshot, prev: Snapshot | None) -> list[str]:
        if prev is None:
            return []
        rising = []
        for side, now_c, before_c, names in (
            ("host", snap.host, prev.host, (*HOST_ERRORS, *HOST_LATE)),
            ("board", snap.board, prev.board, BOARD_ERRORS),
        ):
            if now_c is None or before_c is None:
                continue
            now_e, before_e = _errors(now_c, names), _errors(before_c, names)
            for name in names:
                if now_e[name] > before_e[name]:  # lower: the counters restarted (reconnect, board reset)
                    why = " (a busy host: setpoints half their slack late)" if name in HOST_LATE else ""
                    rising.append(f"{side} {name} +{now_e[name] - before_e[name]}{why}")
        return rising

    @staticmethod
    def _silent(snap: Snapshot) -> bool:
        due, age = snap.feedback_expected_s, snap.feedback_age_s
        return due is not None and age is not None and age > due

    def _link(self, snap: Snapshot, prev: Snapshot | None) -> Report:
        values: list[tuple[str, str]] = [("url", snap.url), ("connection", snap.connection)]
        if snap.connection != "connected":
            values += [("last error", snap.connection_error or "-"), ("failed attempts", str(snap.attempts))]
        values.append(("reconnects", str(snap.reconnects)))
        if snap.mode:
            values.append(("feedback mode", snap.mode))
        if snap.feedback_hz is not None:
            values.append(("feedback rate (Hz)", f"{snap.feedback_hz:.1f}"))
        if snap.feedback_age_s is not None:
            values.append(("last feedback (s ago)", f"{snap.feedback_age_s:.3f}"))
        dt = snap.time_s - prev.time_s if prev is not None else None
        if snap.host is not None:
            h, ph = snap.host, prev.host if prev is not None else None
            values += [
                ("host frames received", str(h.frames_received)),
                ("host frames received/s", _rate(h.frames_received, ph.frames_received if ph else None, dt)),
                ("host frames sent", str(h.frames_sent)),
                ("host frames sent/s", _rate(h.frames_sent, ph.frames_sent if ph else None, dt)),
            ]
            values += [(f"host {name}", str(value)) for name, value in _errors(h, (*HOST_ERRORS, *HOST_LATE)).items()]
            values += [("host retries", str(h.retries)), ("host request timeouts", str(h.request_timeouts))]
            if h.rtt is not None:
                r = h.rtt
                values.append(
                    (
                        "rtt last/min/mean/max (ms)",
                        "/".join(f"{v * 1e3:.2f}" for v in (r.last_s, r.min_s, r.mean_s, r.max_s)),
                    )
                )
            if h.clock_offset_us is not None:
                values.append(("clock offset (ms)", f"{h.clock_offset_us / 1e3:.3f}"))
            if h.clock_drift_ppm is not None:
                values.append(("clock drift (ppm)", f"{h.clock_drift_ppm:.1f}"))
        if snap.board is not None:
            b = snap.board
            pb, bdt = None, None
            if prev is not None and prev.board is not None and prev.board_time_s and snap.board_time_s:
                pb, bdt = prev.board, snap.board_time_s - prev.board_time_s
            values += [
                ("board frames received", str(b.frames_ok)),
                ("board frames received/s", _rate(b.frames_ok, pb.frames_ok if pb else None, bdt)),
                ("board frames sent", str(b.frames_sent)),
                ("board frames sent/s", _rate(b.frames_sent, pb.frames_sent if pb else None, bdt)),
                ("board duplicates", str(b.duplicates)),
            ]
            values += [(f"board {name}", str(value)) for name, value in _errors(b, BOARD_ERRORS).items()]
        if snap.connection != "connected":
            level = ERROR
            message = f"no connection to {snap.url}: {snap.connection_error or snap.connection}"
            if snap.connection in ("connecting", "reconnecting"):
                message += f" (reconnecting, {snap.attempts} failed attempts)"
        elif self._silent(snap):
            level = ERROR
            message = f"no FEEDBACK for {snap.feedback_age_s:.1f} s: the cable may be cut or the board hung"
        else:
            rising = self._rising(snap, prev)
            level, message = (WARN, "link errors rising: " + ", ".join(rising)) if rising else (OK, "connected")
        return Report(level, f"{self.node_name}: link", message, snap.url, tuple(values))

    def _robot(self, snap: Snapshot) -> Report:
        values: list[tuple[str, str]] = []
        ident = snap.identity
        hardware_id = snap.url
        if ident is not None:
            hardware_id = f"{ident.robot_name or 'RoverLink'} on {snap.url}"
            values += [
                ("robot", ident.robot_name),
                ("firmware", ident.version),
                ("board", ident.board.name),
                ("protocol", f"v{ident.protocol_version}, spec hash 0x{ident.spec_hash:08X}"),
                ("capabilities", str(ident.capabilities.name or int(ident.capabilities)).replace("|", " ")),
                ("boot_id", f"0x{ident.boot_id:08X}"),
                ("watchdog (ms)", str(ident.watchdog_ms)),
            ]
        reason = snap.failsafe
        values += [
            ("state", snap.state or snap.connection),
            ("failsafe", "-" if reason is None else reason.name),
            ("failsafes", str(snap.failsafes)),
            ("last failsafe", _ago(snap.last_failsafe, snap.time_s)),
            ("board resets", str(snap.resets)),
            ("last reset", _ago(snap.last_reset, snap.time_s)),
            ("cmd_vel refused", str(snap.refused)),
            ("last refusal", snap.last_refusal or "-"),
        ]
        if snap.tf:
            values.append(("tf", snap.tf))
        values += [(f"mismatch {i + 1}", text) for i, text in enumerate(snap.mismatches)]
        if snap.connection != "connected":
            level, message = STALE, "no connection"
        elif reason is not None:
            level = ERROR
            message = f"FAILSAFE ({reason.name}): {failsafe_meaning(reason)}; call ~/arm"
        elif snap.state == "connecting":
            level, message = WARN, "re-opening the session after a board reset"
        elif snap.last_reset is not None and not snap.rearmed_since_reset and snap.state != "armed":
            level, message = WARN, f"board reset ({snap.last_reset.text}): disarmed, call ~/arm"
        elif snap.mismatches:
            count = len(snap.mismatches)
            level = WARN
            message = f"{snap.state}; the board differs from the robot file (allow_mismatch, {count}): " + "; ".join(
                snap.mismatches
            )
        else:
            level, message = OK, snap.state
        return Report(level, f"{self.node_name}: robot", message, hardware_id, tuple(values))
