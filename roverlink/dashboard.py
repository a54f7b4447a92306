"""What the monitor and teleop show: a snapshot of a robot, and its text.

`Dashboard` reads only: identity, state and failsafe reason, the latest FEEDBACK (measured wheel
speeds, efforts, steering), odometry, both sides' link statistics with rates, RTT and clock drift,
the last LOG lines, and the host-side sensors when there are any (roverlink.sensors: scan rate,
points, nearest obstacle; IMU attitude and rates; camera fps and dropped frames). It never arms
or commands. `poll()` asks the board for its LINK_STATS
once a second (a reliable request; the only thing it sends besides the session's own PINGs).
`lines()` is the plain text (the fallback when stdout is not a terminal, and the text screenshot);
the Textual apps in roverlink.tui show the same sections.
"""

from __future__ import annotations

import collections
import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass, field

from host_sdk import FeedbackSample, LinkStatistics, Robot, RoverLinkError
from host_sdk.enums import LogLevel, Status
from host_sdk.recording.sources import board_counters, link_rates
from host_sdk.sensors.hub import Sensors, SensorStatus

LOG_LINES = 8
BOARD_STATS_PERIOD_S = 1.0


@dataclass
class Setpoint:
    """What the program showing the dashboard commanded (teleop); None in the read-only monitor."""

    speeds_m_s: tuple[float, ...]
    linear_m_s: float
    angular_rad_s: float


@dataclass
class Snapshot:
    title: str
    url: str
    state: str
    failsafe: str | None
    feedback: FeedbackSample | None
    feedback_age_s: float | None
    host: LinkStatistics
    host_rates: dict[str, float]
    board: dict[str, int] | None
    board_rates: dict[str, float]
    logs: list[str] = field(default_factory=list)
    setpoint: Setpoint | None = None
    sensors: SensorStatus | None = None


class Dashboard:
    """Collects a robot's state for display; thread-safe (LOG lines arrive on the I/O thread)."""

    def __init__(self, robot: Robot, *, board_stats: bool = True, sensors: Sensors | None = None) -> None:
        self.robot = robot
        self.board_stats = board_stats
        self.sensors = sensors if sensors is not None and not sensors.empty else None
        self._logs: collections.deque[str] = collections.deque(maxlen=LOG_LINES)
        self._lock = threading.Lock()
        self._unsubscribe = robot.on_log(self._on_log)
        self._last_host: tuple[float, LinkStatistics] | None = None
        self._host_rates: dict[str, float] = {}
        self._board: dict[str, int] | None = None
        self._last_board: tuple[float, dict[str, int]] | None = None
        self._board_rates: dict[str, float] = {}
        self.setpoint: Setpoint | None = None

    def _on_log(self, level: LogLevel, text: str) -> None:
        with self._lock:
            self._logs.append(f"{level.name:<5} {text}")

    def close(self) -> None:
        self._unsubscribe()

    def poll(self) -> None:
        """Update the rates (and once a second the board's counters); read virtual-clock sensors."""
        if self.sensors is not None:
            self.sensors.poll()
        now = self.robot.now()
        stats = self.robot.stats
        last = self._last_host
        if last is None or now - last[0] >= BOARD_STATS_PERIOD_S:
            if last is not None:
                self._host_rates = link_rates(last[1], stats, now - last[0])
            self._last_host = (now, stats)
            if self.board_stats:
                self._poll_board(now)

    def _poll_board(self, now: float) -> None:
        try:
            board = board_counters(self.robot)
        except RoverLinkError:
            board = None
        if board is None:
            return
        prev = self._last_board
        if prev is not None and now > prev[0]:
            dt = now - prev[0]
            self._board_rates = {
                "frames_ok_per_s": (board["frames_ok"] - prev[1]["frames_ok"]) / dt,
                "frames_sent_per_s": (board["frames_sent"] - prev[1]["frames_sent"]) / dt,
            }
        self._last_board = (now, board)
        self._board = board

    def snapshot(self) -> Snapshot:
        robot = self.robot
        ident = robot.identity
        failsafe = robot.failsafe
        with self._lock:
            logs = list(self._logs)
        return Snapshot(
            title=f"{ident.robot_name or 'robot'} {ident.version} on {ident.board.name}, boot 0x{ident.boot_id:08X}",
            url=robot.url,
            state=robot.state,
            failsafe=failsafe.name if failsafe is not None else None,
            feedback=robot.feedback,
            feedback_age_s=robot.feedback_age_s,
            host=robot.stats,
            host_rates=dict(self._host_rates),
            board=self._board,
            board_rates=dict(self._board_rates),
            logs=logs,
            setpoint=self.setpoint,
            sensors=self.sensors.status() if self.sensors is not None else None,
        )


def _fmt(values: Sequence[float], unit: str = "", digits: int = 3) -> str:
    return "  ".join(f"{v:+.{digits}f}" for v in values) + (f" {unit}" if unit else "")


def state_lines(s: Snapshot) -> list[str]:
    fb = s.feedback
    state = s.state.upper() + (f" ({s.failsafe})" if s.failsafe else "")
    lines = [f"{s.title}", f"  {s.url}   state {state}"]
    if fb is None:
        return [*lines, "  no FEEDBACK yet"]
    flags = [f.name for f in Status if f in fb.status and f.name]
    age = f"{s.feedback_age_s * 1000:.0f} ms ago" if s.feedback_age_s is not None else ""
    lines.append(f"  status {' '.join(flags) or '-'}   tick {fb.tick}   {age}")
    return lines


def motion_lines(s: Snapshot) -> list[str]:
    fb = s.feedback
    if fb is None:
        return []
    sp = s.setpoint
    setpoint = _fmt(sp.speeds_m_s, "m/s") if sp is not None else "- (the monitor never commands)"
    lines = [
        f"  setpoint   {setpoint}",
        f"  measured   {_fmt(fb.wheel_speeds_m_s, 'm/s')}",
        f"  effort     {_fmt(fb.efforts, '', 2)}",
        f"  steering   {math.degrees(fb.steering_rad):+.1f} deg",
        f"  counts     {'  '.join(str(c) for c in fb.encoder_counts)}",
    ]
    if fb.pose is not None:
        p = fb.pose
        lines.append(
            f"  odometry   x {p.x_m:+.3f} m  y {p.y_m:+.3f} m  heading {math.degrees(p.heading_rad):+.1f} deg"
            f"  v {p.linear_m_s:+.2f} m/s  w {p.angular_rad_s:+.2f} rad/s"
        )
    return lines


def link_lines(s: Snapshot) -> list[str]:
    h = s.host
    r = s.host_rates
    rtt = f"{h.rtt.last_s * 1000:.2f} ms (min {h.rtt.min_s * 1000:.2f})" if h.rtt is not None else "-"
    drift = f"{h.clock_drift_ppm:+.1f} ppm" if h.clock_drift_ppm is not None else "-"
    lines = [
        f"  host   rx {h.frames_received} frames ({r.get('frames_received_per_s', 0):.0f}/s, "
        f"{r.get('bytes_received_per_s', 0):.0f} B/s)  tx {h.frames_sent} ({r.get('frames_sent_per_s', 0):.0f}/s)",
        f"         crc {h.crc_errors}  cobs {h.cobs_errors}  length {h.length_errors}  gaps {h.seq_gaps}  "
        f"retries {h.retries}  nacks {sum(h.nacks.values())}  resets {h.resets_detected}",
        f"         rtt {rtt}  clock drift {drift}",
    ]
    b = s.board
    if b is not None:
        lines.append(
            f"  board  rx {b['frames_ok']} frames ({s.board_rates.get('frames_ok_per_s', 0):.0f}/s)  "
            f"tx {b['frames_sent']} ({s.board_rates.get('frames_sent_per_s', 0):.0f}/s)  crc {b['crc_errors']}  "
            f"cobs {b['cobs_errors']}  gaps {b['seq_gaps']}  dup {b['duplicates']}  overruns {b['rx_overruns']}"
        )
    return lines


def _opt(value: float | None, fmt: str) -> str:
    return "-" if value is None else format(value, fmt)


def sensor_lines(s: Snapshot) -> list[str]:
    """The sensors' section (empty without sensors)."""
    st = s.sensors
    if st is None:
        return []
    out = []
    if (li := st.lidar) is not None:
        nearest = (
            f"nearest {li.nearest_m:.3f} m at {li.nearest_bearing_deg:+.0f} deg"
            if li.nearest_m is not None and li.nearest_bearing_deg is not None
            else "nearest -"
        )
        out.append(
            f"  lidar   {li.model}  {_opt(li.rate_hz, '.1f')} scans/s  {li.points} points ({li.valid} returns)  "
            f"{nearest}  errors {li.errors}"
        )
    if (imu := st.imu) is not None:
        attitude = rates = "-"
        if imu.angles_deg is not None:
            roll, pitch, yaw = imu.angles_deg
            attitude = f"roll {roll:+.1f}  pitch {pitch:+.1f}  yaw {yaw:+.1f} deg"
        if imu.rates_dps is not None:
            rates = " ".join(f"{w:+.1f}" for w in imu.rates_dps) + " deg/s"
        out.append(f"  imu     {_opt(imu.rate_hz, '.0f')} Hz  {attitude}  rates {rates}  errors {imu.errors}")
    if (cam := st.camera) is not None:
        size = f"{cam.size[0]}x{cam.size[1]}" if cam.size is not None else "-"
        out.append(f"  camera  {size}  {_opt(cam.fps, '.1f')} fps  {cam.frames} frames  dropped {cam.dropped}")
    out += [f"  stopped: {error}" for error in st.errors]
    return out


def lines(s: Snapshot) -> list[str]:
    """The whole dashboard as text."""
    sensors = sensor_lines(s)
    out = state_lines(s) + motion_lines(s) + (["sensors:", *sensors] if sensors else [])
    out += ["link:", *link_lines(s), "log:"]
    out += [f"  {line}" for line in s.logs] or ["  (none)"]
    return out


def one_line(s: Snapshot) -> str:
    """A compact periodic line for logs (stdout not a terminal)."""
    fb = s.feedback
    parts = [s.state + (f"({s.failsafe})" if s.failsafe else "")]
    if fb is not None:
        parts.append("v " + ",".join(f"{v:+.3f}" for v in fb.wheel_speeds_m_s))
        parts.append("u " + ",".join(f"{u:+.2f}" for u in fb.efforts))
        if fb.pose is not None:
            parts.append(f"pose {fb.pose.x_m:+.3f},{fb.pose.y_m:+.3f},{math.degrees(fb.pose.heading_rad):+.1f}")
    h = s.host
    parts.append(f"rx {s.host_rates.get('feedback_received_per_s', 0):.0f}/s crc {h.crc_errors}")
    if h.rtt is not None:
        parts.append(f"rtt {h.rtt.last_s * 1000:.2f}ms")
    st = s.sensors
    if st is not None:
        if st.lidar is not None:
            parts.append(f"scan {_opt(st.lidar.rate_hz, '.1f')}/s near {_opt(st.lidar.nearest_m, '.2f')}m")
        if st.imu is not None and st.imu.angles_deg is not None:
            parts.append(f"yaw {st.imu.angles_deg[2]:+.1f}")
        if st.camera is not None:
            parts.append(f"cam {_opt(st.camera.fps, '.0f')}fps drop {st.camera.dropped}")
    return "  ".join(parts)
