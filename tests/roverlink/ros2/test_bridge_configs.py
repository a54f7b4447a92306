"""The names the generated parameters files give SLAM Toolbox and Nav2 (roverlink.ros2.robotfacts.TOPICS)
are the ones a running node uses: a real bridge process started with a reference robot's
examples/ros2/<robot>/roverlink.yaml, its topics read from the ROS graph."""

from __future__ import annotations

import uuid
from pathlib import Path

from ros_env import ROOT, require_ros

require_ros()

from bridge_harness import BridgeProcess, Probe  # noqa: E402
from rclpy.qos import qos_profile_sensor_data  # noqa: E402
from sensor_msgs.msg import LaserScan  # noqa: E402

from roverlink.ros2.params import BY_NAME  # noqa: E402
from roverlink.ros2.robotfacts import TOPICS  # noqa: E402

ROBOT = "diffdrive-bts7960"
URL = f"emu://{ROBOT}?seed=3&world=random:2&lidar=rplidar-a1&imu=jy901"


def test_the_node_publishes_and_subscribes_the_names_the_configs_use(ros: None, tmp_path: Path) -> None:
    ns = f"/configs_{uuid.uuid4().hex[:6]}"
    params_file = ROOT / "examples" / "ros2" / ROBOT / "roverlink.yaml"
    # The file names a real lidar port; against the emulator the emulated lidar stands in for it
    # (after the file: the last value wins).
    proc = BridgeProcess(ns, URL, tmp_path, extra=["--params-file", str(params_file), "-p", "lidar_url:=''"])
    probe = Probe(ns)
    probe.subscribe("scan", LaserScan, TOPICS["scan"], qos_profile_sensor_data)
    try:
        scan = probe.wait_message("scan", timeout_s=30)
        assert scan.header.frame_id == BY_NAME["lidar_frame"].default
        assert probe.call("arm").success  # in lockstep the board reports while it is driven
        odom = probe.wait_message("odom")
        assert (odom.header.frame_id, odom.child_frame_id) == (
            BY_NAME["odom_frame"].default,
            BY_NAME["base_frame"].default,
        )

        def graph() -> tuple[set[str], set[str]] | None:
            pubs = {name for name, _ in probe.node.get_publisher_names_and_types_by_node("roverlink", ns)}
            subs = {name for name, _ in probe.node.get_subscriber_names_and_types_by_node("roverlink", ns)}
            wanted = {f"{ns}/{TOPICS[t]}" for t in ("odom", "scan", "imu", "joint_states")}
            return (pubs, subs) if wanted <= pubs and f"{ns}/{TOPICS['cmd_vel']}" in subs else None

        probe.wait_for("the node's topics on the graph", graph, 10)
    except BaseException:
        print(proc.log())
        raise
    finally:
        probe.close()
        assert proc.stop() == 0
