"""The 1 m square on the board's own odometry, against the plant's truth.

The host drives each side until the odometry it integrates from FEEDBACK's counts (host_sdk's
`Odometry`, as `Robot` does) says 1 m, and each corner until it says 90 degrees: a turn in place
on a differential robot, a full-lock arc on the Ackermann car. Then it stops, and the pose the
counts give is compared with where the plant really is: what a robot's odometry is worth depends
on the firmware counting every edge and reporting it with the right time and steering.
"""

from __future__ import annotations

import math

from conformance_backends import Host, Truth, base_profile
from conformance_scenarios import TICK_MS, open_session

from host_sdk import messages
from host_sdk.kinematics import Ackermann
from host_sdk.odometry import Odometry
from host_sdk.profiles import kinematics_for
from protocol.generated.profiles import PROFILES

SIDE_M = 1.0
SPEED_MM_S = 300
TURN_MM_S = 150
"""Each wheel's speed turning in place (differential)."""
STEER_FRACTION = 0.9
"""Of the car's steering range, at the corners (Ackermann)."""
SETTLE_MS = 600


def _relative(truth: Truth, start: Truth) -> tuple[float, float, float]:
    """The plant's pose in the frame it started in (as odometry counts from there)."""
    dx, dy = truth.x_m - start.x_m, truth.y_m - start.y_m
    c, s = math.cos(-start.theta_rad), math.sin(-start.theta_rad)
    dth = math.atan2(math.sin(truth.theta_rad - start.theta_rad), math.cos(truth.theta_rad - start.theta_rad))
    return c * dx - s * dy, s * dx + c * dy, dth


def sc_square(h: Host, profile: str) -> dict[str, object]:
    open_session(h)
    p = PROFILES[base_profile(profile)]
    kinematics = kinematics_for(base_profile(profile))
    car = isinstance(kinematics, Ackermann)
    steer = int(STEER_FRACTION * (p.config.steering_max_cdeg - p.config.steering_center_cdeg) * math.pi / 18)
    if car:  # the ESC's arming window holds the drive at rest first
        for _ in range(p.config.esc_arm_ms // TICK_MS):
            h.send(messages.SetAckermann(0, 0))
            h.run_ms(TICK_MS)
    # The three commands of the course: at rest, along a side, round a corner.
    if car:
        rest, side, corner = (messages.SetAckermann(v, a) for v, a in ((0, 0), (SPEED_MM_S, 0), (SPEED_MM_S, steer)))
    else:
        rest, side, corner = (
            messages.SetWheelSpeeds(left, right)
            for left, right in ((0, 0), (SPEED_MM_S, SPEED_MM_S), (-TURN_MM_S, TURN_MM_S))
        )
    odometry = Odometry(kinematics)
    seen_us = h.b.now_us
    start = h.b.truth()

    def tick(command: messages.Message) -> tuple[float, float, float]:
        nonlocal seen_us
        h.send(command)
        h.run_ms(TICK_MS)
        for t, m in h.since(messages.Feedback, seen_us):
            assert isinstance(m, messages.Feedback)
            steering = m.steering_mrad / 1000 if car else 0.0
            odometry.update(m.encoder_counts, m.mcu_time_us, steering)
            seen_us = t + 1
        pose = odometry.pose
        return pose.x_m, pose.y_m, pose.theta_rad

    x, y, theta = tick(rest)
    heading = theta
    for _ in range(4):
        x0, y0 = x, y
        while math.hypot(x - x0, y - y0) < SIDE_M:
            x, y, theta = tick(side)
        heading += math.pi / 2
        while theta < heading:
            x, y, theta = tick(corner)
    for _ in range(SETTLE_MS // TICK_MS):
        x, y, theta = tick(rest)
    tx, ty, tth = _relative(h.b.truth(), start)
    return {
        "odometry": (x, y, theta),
        "truth": (tx, ty, tth),
        "position_error_m": math.hypot(x - tx, y - ty),
        "heading_error_deg": math.degrees(abs(math.atan2(math.sin(theta - tth), math.cos(theta - tth)))),
    }
