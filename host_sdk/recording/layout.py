"""The Foxglove layout shipped for RoverLink recordings (docs/foxglove-layout.json).

Left: the 3D panel following base_link in the odom frame, with the odometry pose, the path and
the lidar's scan around the robot; under it the camera's image. Right: plots of the wheel speeds
(and setpoints when the recording program commanded), efforts, the IMU's yaw and yaw rate, and
the link's rates; below, the firmware's LOG lines and the latest FEEDBACK with every field. A
panel whose topic is not in a recording (no camera, no IMU) stays empty. Regenerate the file after changing this module:

    python -m host_sdk.recording.layout > docs/foxglove-layout.json
"""

from __future__ import annotations

import json
from typing import Any

from host_sdk.extras import require
from host_sdk.recording.schemas import (
    FRAME_BASE,
    FRAME_ODOM,
    TOPIC_FEEDBACK,
    TOPIC_IMAGE,
    TOPIC_IMU,
    TOPIC_LINK,
    TOPIC_LOG,
    TOPIC_ODOMETRY,
    TOPIC_PATH,
    TOPIC_SCAN,
    TOPIC_SETPOINT,
    TOPIC_WHEELS,
)


def layout() -> Any:
    fl = require("foxglove.layouts", "foxglove", "the Foxglove layout")

    def plot(title: str, series: list[tuple[str, str]]) -> Any:
        paths = [fl.PlotSeries(value=value, label=label) for value, label in series]
        return fl.PlotPanel(title=title, config=fl.PlotConfig(paths=paths, show_legend=True))

    three_d = fl.ThreeDeePanel(
        title="odometry",
        config=fl.ThreeDeeConfig(
            follow_tf=FRAME_BASE,
            fixed_frame=FRAME_ODOM,
            topics={
                TOPIC_ODOMETRY: fl.BaseRendererPoseTopicSettings(visible=True, type="arrow"),
                TOPIC_PATH: fl.BaseRendererPosesTopicSettings(visible=True, type="line", line_width=0.02),
                TOPIC_SCAN: fl.BaseRendererLaserScanTopicSettings(
                    visible=True, point_size=4.0, color_mode="flat", flat_color="#ff3d00"
                ),
            },
        ),
    )
    camera = fl.ImagePanel(
        title="camera", config=fl.ImageConfig(image_mode=fl.ImageModeConfig(image_topic=TOPIC_IMAGE))
    )
    speeds = plot(
        "wheel speeds (m/s)",
        [
            (f"{TOPIC_WHEELS}.speed_m_s[0]", "measured 0"),
            (f"{TOPIC_WHEELS}.speed_m_s[1]", "measured 1"),
            (f"{TOPIC_SETPOINT}.speed_m_s[0]", "setpoint 0"),
            (f"{TOPIC_SETPOINT}.speed_m_s[1]", "setpoint 1"),
        ],
    )
    efforts = plot(
        "efforts (-1..1)", [(f"{TOPIC_WHEELS}.effort[0]", "wheel 0"), (f"{TOPIC_WHEELS}.effort[1]", "wheel 1")]
    )
    imu = plot(
        "IMU (rad, rad/s)",
        [(f"{TOPIC_IMU}.angles_rad[2]", "yaw"), (f"{TOPIC_IMU}.angular_velocity[2]", "yaw rate")],
    )
    link = plot(
        "link (per second)",
        [
            (f"{TOPIC_LINK}.rates.feedback_received_per_s", "FEEDBACK"),
            (f"{TOPIC_LINK}.rates.crc_errors_per_s", "CRC errors"),
            (f"{TOPIC_LINK}.host.rtt_ms", "RTT ms"),
        ],
    )
    log = fl.LogPanel(title="firmware LOG", config=fl.LogConfig(topic_to_render=TOPIC_LOG))
    raw = fl.RawMessagesPanel(title="FEEDBACK", config=fl.RawMessagesConfig(topic_path=TOPIC_FEEDBACK))

    def column(*panels: Any) -> Any:
        return fl.SplitContainer(direction="column", items=[fl.SplitItem(content=p) for p in panels])

    left = fl.SplitContainer(
        direction="column",
        items=[fl.SplitItem(proportion=3, content=three_d), fl.SplitItem(proportion=2, content=camera)],
    )
    right = column(speeds, efforts, imu, link)
    bottom = fl.SplitContainer(direction="row", items=[fl.SplitItem(content=log), fl.SplitItem(content=raw)])
    top = fl.SplitContainer(
        direction="row", items=[fl.SplitItem(proportion=3, content=left), fl.SplitItem(proportion=2, content=right)]
    )
    return fl.Layout(
        content=fl.SplitContainer(
            direction="column",
            items=[fl.SplitItem(proportion=3, content=top), fl.SplitItem(proportion=1, content=bottom)],
        )
    )


def layout_json() -> str:
    """The layout as the indented JSON file Foxglove imports (Layouts > Import from file)."""
    return json.dumps(json.loads(layout().to_json()), indent=2) + "\n"


if __name__ == "__main__":
    print(layout_json(), end="")
