"""Print odometry and wheel feedback as the robot turns a slow circle, using a feedback callback.

.venv/bin/python examples/read_odometry.py                                          # the emulated diff-drive car
.venv/bin/python examples/read_odometry.py "emu://diffdrive-bts7960?clock=virtual"  # the SLAM robot (lockstep)
.venv/bin/python examples/read_odometry.py "emu://picar?clock=virtual"              # the Ackermann PiCar
.venv/bin/python examples/read_odometry.py /dev/ttyACM0                             # a real board
"""

from __future__ import annotations

import math
import sys

from host_sdk import FeedbackSample, Robot


def main(url: str = "emu://", seconds: float = 3.0) -> None:
    with Robot.connect(url) as robot:
        samples: list[FeedbackSample] = []
        robot.on_feedback(samples.append)  # every FEEDBACK, on the SDK's I/O thread
        robot.arm()
        end = robot.now() + seconds
        while robot.now() < end:
            robot.drive(0.2, 0.5, clamp=True)  # an Ackermann robot steers as close as it can
            fb = robot.wait_feedback()
            if fb.index % 10 == 0 and fb.pose is not None:
                p = fb.pose
                print(
                    f"t={fb.host_time_s:8.3f} s  x={p.x_m:+.3f} y={p.y_m:+.3f} th={math.degrees(p.theta_rad):+6.1f} deg"
                    f"  v={p.linear_m_s:.2f} m/s w={p.angular_rad_s:+.2f} rad/s  counts={fb.encoder_counts}"
                )
        robot.stop()
        s = robot.stats
        rtt = f"{s.rtt.min_s * 1000:.1f} ms" if s.rtt else "-"
        print(f"{len(samples)} feedback frames, {s.seq_gaps} lost, round trip {rtt}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
