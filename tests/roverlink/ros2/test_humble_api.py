"""The ROS 2 bridge uses only what ROS 2 Humble has, so it runs on Humble as on Jazzy.

Every rclpy name, keyword argument and message field the bridge uses (read from its source by
ros_api.py) must be on humble_api.toml, the list tools/ros2_humble_api.py checked against Humble's
rclpy and message definitions at the commits the list names. Plain Python: no ROS needed.
"""

from __future__ import annotations

import re
import sys
import textwrap
from pathlib import Path

from ros_api import Api, Use, bridge_uses

from protocol.toml import tomllib

ROOT = Path(__file__).resolve().parents[3]
LIST = Path(__file__).with_name("humble_api.toml")
DATA = tomllib.loads(LIST.read_text(encoding="utf-8"))
API = Api(DATA["rclpy"], DATA["messages"], DATA["services"])
REPOS = ("rclpy", "common_interfaces", "rcl_interfaces", "geometry2")


def _lines(uses: set[Use], keys: set[str]) -> list[str]:
    return sorted({f"{u.where}: {u.key}" for u in uses if u.key in keys})


def test_the_list_names_the_humble_commits_it_was_checked_against() -> None:
    checked = DATA["checked_against"]
    assert checked["branch"] == "humble"
    for repo in REPOS:
        assert re.fullmatch(r"[0-9a-f]{40} \(\d+\.\d+\.\d+\)", checked[repo]), (repo, checked.get(repo))


def test_the_bridge_uses_nothing_that_is_not_on_the_humble_list() -> None:
    uses = bridge_uses(API, ROOT)
    unknown = {u.key for u in uses} - API.known()
    assert _lines(uses, unknown) == [], (
        "the bridge uses what humble_api.toml does not list: check each against ROS 2 Humble's sources "
        "(tools/ros2_humble_api.py) and add it, or use what both Humble and Jazzy have"
    )


def test_every_entry_is_one_the_bridge_uses() -> None:
    """The list is what the bridge uses: an entry it no longer uses is removed."""
    used = {u.key for u in bridge_uses(API, ROOT)}
    fields_used = {key.rsplit(".", 1)[0] for key in used if "/" in key}
    stale = {key for key in API.known() if "/" not in key and key not in used}  # rclpy
    stale |= {f"{m}.{f}" for m, fields in API.message_fields().items() for f in fields} - used
    stale |= {m for m in DATA["messages"] if m not in used and m not in fields_used}
    stale |= {s for s in DATA["services"] if s not in used}
    assert sorted(stale) == []


def test_the_bridge_reaches_the_fields_it_fills_through_its_converters() -> None:
    """Messages the converters take duck-typed are followed from where they are made."""
    keys = {u.key: u.where for u in bridge_uses(API, ROOT)}
    assert keys["builtin_interfaces/Time.nanosec"].startswith("roverlink/ros2/convert.py")
    assert keys["sensor_msgs/LaserScan.time_increment"].startswith("roverlink/ros2/convert.py")
    assert keys["std_srvs/SetBool_Request.data"].startswith("roverlink/ros2/simulation.py")
    assert keys["geometry_msgs/Vector3.z"].startswith("roverlink/ros2/")
    assert "rclpy.node.Node.create_timer" in keys and "rclpy.time.Time.nanoseconds" in keys


BRIDGE_MODULE = """
    from typing import Any

    from geometry_msgs.msg import Twist, TwistStamped
    from rclpy.event_handler import PublisherEventCallbacks
    from rclpy.node import Node
    from std_msgs.msg import Header


    def fill(msg: Any) -> None:
        msg.seq = 1  # ROS 1's Header had it


    class Bridge(Node):
        def __init__(self, stamped: bool) -> None:
            super().__init__("x", parameter_overrides=[], enable_rosout=False)
            self.create_timer(1.0, self._tick, autostart=False)
            self.create_subscription(TwistStamped if stamped else Twist, "cmd_vel", self._on_cmd_vel, 10)
            self.stamped = stamped
            fill(Header())

        def _tick(self) -> None:
            self.get_clock().now().nanoseconds_since_epoch

        def _on_cmd_vel(self, msg: Any) -> None:
            twist = msg.twist if self.stamped else msg
            twist.linear.x
            twist.linear.w
"""


def test_a_name_humble_lacks_is_found_wherever_the_bridge_uses_it(tmp_path: Path) -> None:
    module = tmp_path / "roverlink" / "ros2" / "bridge.py"
    module.parent.mkdir(parents=True)
    module.write_text(textwrap.dedent(BRIDGE_MODULE), encoding="utf-8")
    unknown = {u.key for u in bridge_uses(API, tmp_path)} - API.known()
    assert unknown == {
        "rclpy.event_handler.PublisherEventCallbacks",  # Iron's new module (Humble: rclpy.qos_event)
        "rclpy.node.Node(enable_rosout=)",
        "rclpy.node.Node.create_timer(autostart=)",  # Jazzy's keyword
        "rclpy.time.Time.nanoseconds_since_epoch",
        "std_msgs/Header.seq",  # through a helper taking the message as Any
        "geometry_msgs/Vector3.w",  # in a callback, on a Twist or a TwistStamped's twist
    }


def test_the_source_check_reads_message_definitions_as_humble_writes_them() -> None:
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        from ros2_humble_api import message_fields
    finally:
        sys.path.remove(str(ROOT / "tools"))
    text = "# a comment\nHeader header\nbyte OK=0\nbyte level  # the level\nfloat64[36] covariance\n"
    text += "KeyValue[] values\nstring<=8 name\nint32 count 5\n"
    assert message_fields(text, "diagnostic_msgs") == {
        "header": "std_msgs/Header",
        "level": "byte",
        "covariance": "float64[36]",
        "values": "diagnostic_msgs/KeyValue[]",
        "name": "string<=8",
        "count": "int32",
    }
