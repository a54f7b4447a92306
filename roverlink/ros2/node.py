"""The `roverlink` ROS 2 node: a RoverLink robot on the ROS 2 graph.

Subscribes `cmd_vel` (and `~/set_pose`); publishes `odom`, `joint_states`, `/tf`, `/tf_static`,
`/diagnostics`, and with sensors `scan`, `imu` and `odometry/filtered`; serves `~/arm`, `~/disarm`
and `~/reset_odometry`. docs/ros2.md has the interface. Threads: the executor runs subscriptions,
services and timers; the SDK's I/O thread publishes each FEEDBACK as it arrives (odometry is
stamped with the board's sample time, so it is published at once, not queued) and, in lockstep,
sends the setpoints (paced on the board's ticks: the executor only replaces the live one); the
connection thread owns the Robot's lifetime (host_sdk.supervisor.connection).
"""

from __future__ import annotations

import dataclasses
import importlib
import logging
import threading
import time
from collections import deque
from collections.abc import Mapping
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data
from sensor_msgs.msg import JointState
from std_srvs.srv import Trigger

from host_sdk import FeedbackSample, Pose, Robot, RobotDescription, RoverLinkError, SessionResetError
from host_sdk.profiles import PROFILES, get_profile
from host_sdk.robot.file_check import MISMATCH_LOGGER
from host_sdk.supervisor.connection import Connection
from host_sdk.transport import Transport
from protocol.generated.enums import FailsafeReason, FeedbackMode
from protocol.robotfile import reference_path
from roverlink.ros2 import convert, fused
from roverlink.ros2 import params as rules
from roverlink.ros2.diagnostics import DiagnosticsBuilder, Event, Snapshot, feedback_expected_s
from roverlink.ros2.driver import Driver, RefusalLog, arm_hint, in_ros_words
from roverlink.ros2.lights import LightsInterface
from roverlink.ros2.params import SPECS, BridgeParams, ParamSpec, mode_for, odom_rate_for, robot_url
from roverlink.ros2.ros_log import RosLogHandler
from roverlink.ros2.sensors import ImuPublisher, LidarPublisher, SensorPublisher
from roverlink.ros2.static_tf import StaticTf

NODE_NAME = "roverlink"
TF_QOS_DEPTH = 100  # what tf2_ros's TransformBroadcaster uses
STREAM_TICK_S = 0.05


def tf_message_type() -> Any:
    """tf2_msgs/TFMessage, or None where tf2_msgs is not installed (ROS 2 from PyPI wheels)."""
    try:
        return importlib.import_module("tf2_msgs.msg").TFMessage
    except ImportError:
        return None


def _descriptor(spec: ParamSpec) -> ParameterDescriptor:
    d = ParameterDescriptor(description=spec.description, dynamic_typing=True)
    if spec.choices:
        d.additional_constraints = "one of: " + ", ".join(spec.choices)
    if spec.low is not None and spec.high is not None and not isinstance(spec.default, list):
        if isinstance(spec.default, int) and not isinstance(spec.default, bool):
            d.integer_range = [IntegerRange(from_value=int(spec.low), to_value=int(spec.high), step=0)]
        else:
            d.floating_point_range = [FloatingPointRange(from_value=spec.low, to_value=spec.high, step=0.0)]
    return d


class BridgeNode(Node):
    def __init__(self, overrides: dict[str, Any] | None = None) -> None:
        super().__init__(
            NODE_NAME,
            parameter_overrides=[Parameter(k, value=v) for k, v in (overrides or {}).items()],
        )
        for spec in SPECS:
            self.declare_parameter(spec.name, spec.default, _descriptor(spec))
        self.params = p = BridgeParams.from_values({s.name: self.get_parameter(s.name).value for s in SPECS})
        # What the command line and parameters files set for this node: rclpy keeps it (Humble and
        # Jazzy alike) but declares only what is asked for, so a name the node lacks would pass unseen.
        given = [name for name in self._parameter_overrides if not self.has_parameter(name)]
        self.parameter_warnings = rules.unknown_parameter_warnings(given)
        self._log_handler = self._route_logs()
        # Read once: a bad file ends the node before it connects (RobotFileError lists the problems).
        self.robot_file = RobotDescription.load(p.robot_file) if p.robot_file else None
        self.params = p = dataclasses.replace(p, url=robot_url(p))
        self.params = p = dataclasses.replace(p, odom_rate=odom_rate_for(p, self._described()))
        self.mode = mode_for(p, self._profile_mode())
        self._pose_covariance = convert.covariance(p.pose_covariance_diagonal)
        self._pose_uncertainty = (0.0, 0.0)
        self._twist_covariance = convert.covariance(p.twist_covariance_diagonal)
        self.lockstep = self.mode == "lockstep"
        self._events: deque[Event] = deque(maxlen=20)
        self._failsafes = 0
        self._resets = 0
        self._rearmed_since_reset = True
        self._last_pose: Pose | None = None
        self._last_odom_ns = 0
        """The last odom stamp published (ns): a sample not after it is not published."""
        self._joints: convert.JointTracker | None = None
        self._kinematics: Any = None
        self._feedback_times: deque[float] = deque(maxlen=200)
        self.extras: list[Any] = []
        """The emulator's interface (ground truth, faults), when the robot is emulated."""
        self.sensors: list[SensorPublisher] = []
        """scan and imu publishers, one thread each (roverlink.ros2.sensors)."""

        self._create_publishers(p)
        cmd_type = TwistStamped if p.use_stamped_vel else Twist
        self.create_subscription(cmd_type, "cmd_vel", self._on_cmd_vel, p.qos_depth)
        self.create_service(Trigger, "~/arm", self._on_arm)
        self.create_service(Trigger, "~/disarm", self._on_disarm)

        self.arm_service = f"{self.get_fully_qualified_name()}/arm"
        self.refusals = RefusalLog(self.get_logger().warning, self.get_logger().info, self.arm_service)
        self.driver: Driver | None = None
        self._driver_lock = threading.Lock()
        self.diagnostics = DiagnosticsBuilder(self.get_fully_qualified_name().lstrip("/"))
        self.connection = Connection(
            self._connect,
            on_connected=self._on_connected,
            on_lost=self._on_lost,
            delay_s=p.reconnect_delay,
            delay_max_s=p.reconnect_delay_max,
            stats_period_s=1.0 / p.diagnostics_rate,
            may_poll_board=self._may_poll_board,
        )
        self.fusion = fused.start(self, self.connection, p, self._emu_options(), (self.tf_pub, self._tf_type))
        self.pose_services = fused.PoseServices(self, self.connection, p, self.fusion)
        self.lights = LightsInterface(self, self.connection)
        # The tick only notices an expired cmd_vel and renews the zero-speed hold, so 20 Hz is
        # enough: the SDK repeats live setpoints itself (in lockstep once per period, paced).
        self.create_timer(STREAM_TICK_S, self._tick)
        self.create_timer(1.0 / p.diagnostics_rate, self._publish_diagnostics)
        self.parameter_warnings += rules.profile_sensor_warnings(p) + rules.link_warnings(p)
        for line in self.parameter_warnings:
            self.get_logger().warning(line)
        self._start_sensors({})  # those named by parameters; an emulated robot's when it connects
        self._publish_static_tf(None)
        self.connection.start()
        self.get_logger().info(f"connecting to {p.url} ({self.mode} feedback at {p.odom_rate} Hz)")
        if p.auto_arm:  # an opt-in that drives again by itself: said once, at the start
            self.get_logger().warning(
                "auto_arm is on: the robot is armed at start and again on the next cmd_vel "
                "after a board reset or a watchdog failsafe"
            )

    def _route_logs(self) -> RosLogHandler:
        """The SDK's and the bridge's Python logs into the ROS log."""
        handler = RosLogHandler(self)
        for name in ("host_sdk", "roverlink.ros2"):
            logging.getLogger(name).addHandler(handler)
            logging.getLogger(name).setLevel(logging.INFO)
        # The differences allowed from the robot file (allow_mismatch) go to the ROS log, once: the
        # `roverlink` command keeps their logger from propagating, and so does the node.
        logging.getLogger(MISMATCH_LOGGER).addHandler(handler)
        logging.getLogger(MISMATCH_LOGGER).propagate = False
        return handler

    def _create_publishers(self, p: BridgeParams) -> None:
        """odom, joint_states, /diagnostics, /tf and /tf_static (the last two need tf2_msgs)."""
        odom_qos = QoSProfile(depth=p.qos_depth, reliability=ReliabilityPolicy.RELIABLE)
        if p.odom_qos == "sensor_data":
            odom_qos = QoSProfile(depth=p.qos_depth, reliability=qos_profile_sensor_data.reliability)
        self.odom_pub = self.create_publisher(Odometry, "odom", odom_qos)
        self.joint_pub = self.create_publisher(JointState, "joint_states", odom_qos)
        self.diag_pub = self.create_publisher(DiagnosticArray, "/diagnostics", QoSProfile(depth=10))
        self._tf_type: Any = tf_message_type() if p.publish_tf else None
        self.tf_pub: Any = None
        if self._tf_type is not None:
            self.tf_pub = self.create_publisher(self._tf_type, "/tf", QoSProfile(depth=TF_QOS_DEPTH))
        if p.publish_tf and self._tf_type is None:
            self.get_logger().warning(
                "publish_tf is true but tf2_msgs is not installed, so /tf is not published: install "
                "ros-$ROS_DISTRO-tf2-msgs from a ROS 2 distribution, or build it into this environment with "
                "`python -m roverlink.ros2.interfaces --prefix $VIRTUAL_ENV` (docs/ros2.md)"
            )
        static_type = tf_message_type() if p.publish_static_tf else None
        self.static_tf = None if static_type is None else StaticTf(self, static_type, p, self.robot_file)

    # -- connecting ----------------------------------------------------------------------------
    def _emu_options(self) -> Any:
        """What an emu:// URL asks for (None for another port)."""
        if not self.params.url.startswith("emu://"):
            return None
        from emulator.transport.inprocess import parse_emu_url  # noqa: PLC0415 (only for emu://)

        return parse_emu_url(self.params.url)

    def _profile_name(self) -> str | None:
        if self.params.profile:
            return self.params.profile
        emu = self._emu_options()
        return None if emu is None else str(emu.profile)

    def _start_sensors(self, endpoints: Mapping[str, str]) -> None:
        """The lidar and IMU the parameters name, or else the emulated ones of an emu:// robot, or
        else the robot file's (their `port`)."""
        p, started = self.params, {s.kind for s in self.sensors}
        own = self.robot_file if self.robot_file is not None and not p.url.startswith("emu://") else None
        files = {"lidar": own.lidar if own else None, "imu": own.imu if own else None}
        ports = {kind: dev.port if dev is not None else "" for kind, dev in files.items()}
        lidar_url = p.lidar_url or endpoints.get("lidar", "") or ports["lidar"]
        if lidar_url and "lidar" not in started:
            emu = self._emu_options() if not p.lidar_url else None
            model = emu.sensors.lidar if emu is not None and emu.sensors is not None else p.lidar_model
            lidar = self.robot_file.lidar if self.robot_file is not None else None
            if lidar is not None and lidar_url == lidar.port:
                model = lidar.model
            baud = rules.sensor_baud(p.lidar_baud, lidar)
            self.sensors.append(LidarPublisher(self, lidar_url, model, p.lidar_frame, p.scan_bins, baud=baud))
        imu_url = p.imu_url or endpoints.get("imu", "") or ports["imu"]
        if imu_url and "imu" not in started:
            imu = self.robot_file.imu if self.robot_file is not None else None
            baud = rules.sensor_baud(p.imu_baud, imu)
            self.sensors.append(ImuPublisher(self, imu_url, p, self.fusion, baud=baud))
        running = {s.kind for s in self.sensors}
        for kind, dev in files.items():
            if dev is not None and not endpoints and kind not in running:
                self.get_logger().warning(
                    f"the robot file has a {kind} but no port for it: set [sensors.{kind}] port (e.g. a "
                    f"/dev/serial/by-id/... path) or the {kind}_url parameter"
                )

    def _publish_static_tf(self, robot: Robot | None) -> None:
        if self.static_tf is not None:
            self.static_tf.update(robot, self._profile_name(), [s.kind for s in self.sensors])

    def _described(self) -> RobotDescription | None:
        """The robot file, or the reference robot's file for a reference profile."""
        if self.robot_file is not None:
            return self.robot_file
        emu = self._emu_options()
        if emu is not None and emu.robot:  # emu://?robot=FILE
            return RobotDescription.load(emu.robot)
        name = self._profile_name()
        return RobotDescription.load(reference_path(name)) if name in PROFILES else None

    def _profile_mode(self) -> str | None:
        if self.robot_file is not None:
            return self.robot_file.feedback.mode
        name = self._profile_name()
        if name is None:
            return None
        try:
            mode = get_profile(name).feedback_mode
        except RoverLinkError:
            return None  # Robot.connect says what is wrong with the name
        return "lockstep" if mode is FeedbackMode.LOCKSTEP else "stream"

    def _connect(self, transport: Transport | None = None) -> Robot:
        """Open the port (or use `transport`, e.g. a benchmark's tap on it) and hand it to the SDK."""
        p = self.params
        return Robot.connect(
            p.url,
            transport=transport,
            profile=p.profile or None,
            robot=self.robot_file,
            allow_mismatch=p.allow_mismatch,
            baud=p.baud,
            watchdog_s=p.watchdog,
            mode="lockstep" if self.lockstep else "stream",
            paced=self.lockstep,  # lockstep's setpoints from the I/O thread, on the board's ticks
            feedback_hz=p.odom_rate,
            timeout_s=p.connect_timeout,
            clamp=p.limit_policy == "clamp",
            auto_rearm=p.auto_arm,
        )

    def _on_connected(self, robot: Robot) -> None:
        p = self.params
        kin = robot.kinematics
        if kin is None:
            raise RoverLinkError(f"{robot.url}: the robot's kinematics are unknown: set the profile parameter")
        if self._last_pose is not None:  # a new connection: odometry carries on where it was
            robot.odometry.reset(self._last_pose.x_m, self._last_pose.y_m, self._last_pose.theta_rad)
        self._kinematics = kin
        names = p.wheel_joints or convert.default_wheel_joints(kin)
        self._joints = convert.JointTracker(kin, names, p.steering_joint)
        with self._driver_lock:
            self.driver = Driver(
                robot,
                self.refusals,
                timeout_s=p.cmd_vel_timeout,
                on_timeout=p.on_timeout,
                lockstep=self.lockstep,
            )
        robot.on_feedback(self._on_feedback)
        robot.on_reset(self._on_reset)
        robot.on_failsafe(self._on_failsafe)
        self.lights.connected(robot)
        ident = robot.identity
        self._event("connected", f"{ident.robot_name} firmware {ident.version}, boot_id 0x{ident.boot_id:08X}")
        self.get_logger().info(f"connected to {ident.robot_name} firmware {ident.version} on {robot.url}")
        if robot.emulator is not None and not self.extras:
            from roverlink.ros2.simulation import EmulatorInterface  # noqa: PLC0415 (only for emu://)

            self.extras.append(EmulatorInterface(self, self.connection, robot, p.odom_frame, p.base_frame))
        self._start_sensors(robot.transport.endpoints)
        self._publish_static_tf(robot)
        if p.auto_arm:
            robot.arm(wait_esc=False)
            self.get_logger().info("armed (auto_arm)")

    def _on_lost(self, robot: Robot, why: str) -> None:
        with self._driver_lock:
            self.driver = None
        self._event("lost", why)

    def _may_poll_board(self) -> bool:
        # A LINK_STATS request feeds the board's watchdog: not while the robot is meant to fail safe.
        driver = self.driver
        return not (self.params.on_timeout == "release" and driver is not None and driver.robot.armed)

    # -- events from the SDK (its I/O thread) ------------------------------------------------------
    def _event(self, kind: str, text: str) -> Event:
        event = Event(time.monotonic(), kind, text)
        self._events.append(event)
        return event

    def _on_reset(self, error: SessionResetError) -> None:
        new = "unknown" if error.new_boot_id is None else f"0x{error.new_boot_id:08X}"
        self._resets += 1
        self._event("reset", f"boot_id 0x{error.old_boot_id:08X} -> {new}")
        self._rearmed_since_reset = self.params.auto_arm
        self.get_logger().warning(f"board reset: {in_ros_words(str(error), self.arm_service)}")

    def _on_failsafe(self, reason: FailsafeReason) -> None:
        self._failsafes += 1
        self._event("failsafe", reason.name)
        self.get_logger().error(f"board in FAILSAFE: {reason.name}")

    def _on_feedback(self, sample: FeedbackSample) -> None:
        robot, joints, kin = self.connection.robot, self._joints, self._kinematics
        pose = sample.pose
        if robot is None or joints is None or pose is None or not self.pose_services.accept(sample):
            return
        self._feedback_times.append(sample.received_s)
        self._last_pose = pose
        p = self.params
        ns = convert.stamp_ns(sample.host_time_s, robot.now(), self.get_clock().now().nanoseconds)
        twist = convert.body_twist(kin, sample)
        if self.fusion is not None:
            self.fusion.on_feedback(sample, twist)
        if ns <= self._last_odom_ns:
            return  # not after the last one published (samples read in a burst at start-up): ROS stamps advance
        self._last_odom_ns = ns
        tf = (self.tf_pub if p.tf_from == "odom" else None, self._tf_type)
        covariances = (self._pose_covariance_of(pose), self._twist_covariance)
        fused.publish_odometry(p, self.odom_pub, tf, ns=ns, pose=pose, twist=twist, covariances=covariances)
        js = JointState()
        convert.fill_joint_state(js, ns=ns, joints=joints.update(sample))
        self.joint_pub.publish(js)

    def _pose_covariance_of(self, pose: Pose) -> list[float]:
        """The configured covariance, grown by the pose's uncertainty (built again only when that changes)."""
        key = (pose.position_uncertainty_m, pose.heading_uncertainty_rad)
        if key != self._pose_uncertainty:
            self._pose_uncertainty = key
            self._pose_covariance = convert.pose_covariance(self.params.pose_covariance_diagonal, pose)
        return self._pose_covariance

    # -- ROS callbacks (executor thread) -----------------------------------------------------------
    def _on_cmd_vel(self, msg: Any) -> None:
        twist = msg.twist if self.params.use_stamped_vel else msg
        driver = self.driver
        if driver is None:
            self.refusals.refused("no connection", f"no connection to {self.params.url}")
            return
        driver.command(float(twist.linear.x), float(twist.angular.z), time.monotonic())

    def _tick(self) -> None:
        driver = self.driver
        if driver is not None:
            driver.tick(time.monotonic())

    def _on_arm(self, request: Any, response: Any) -> Any:
        robot, driver = self.connection.robot, self.driver
        if robot is None or driver is None:
            response.success, response.message = False, f"no connection to {self.params.url}"
            return response
        try:
            driver.clear()
            try:
                robot.arm(wait_esc=False)  # an ESC still in its arming window holds neutral by itself
            except SessionResetError:  # a reset no call had met: on_reset put it in the diagnostics
                robot.arm(wait_esc=False)
        except RoverLinkError as exc:
            response.success, response.message = False, str(exc)
            return response
        driver.hold_off = None
        self._rearmed_since_reset = True
        self.refusals.accepted()
        response.success, response.message = True, "armed"
        self.get_logger().info("armed (~/arm)")
        return response

    def _on_disarm(self, request: Any, response: Any) -> Any:
        robot, driver = self.connection.robot, self.driver
        if robot is None or driver is None:
            response.success, response.message = False, f"no connection to {self.params.url}"
            return response
        driver.hold_off = f"the robot was disarmed through ~/disarm: {arm_hint(self.arm_service)} to drive"
        driver.clear()
        try:
            robot.disarm()
        except RoverLinkError as exc:
            response.success, response.message = False, str(exc)
            return response
        response.success, response.message = True, "disarmed"
        self.get_logger().info("disarmed (~/disarm)")
        return response

    # -- diagnostics ---------------------------------------------------------------------------------
    def snapshot(self) -> Snapshot:
        c, robot = self.connection, self.connection.robot
        now = time.monotonic()
        # list() copies in one step under the GIL: the SDK's thread appends to these meanwhile.
        last = {e.kind: e for e in list(self._events)}
        times = [t for t in list(self._feedback_times) if t > now - 2.0]
        rate = (len(times) - 1) / (times[-1] - times[0]) if len(times) > 2 and times[-1] > times[0] else None
        tf = "off" if not self.params.publish_tf else ("published" if self.tf_pub else "not published: no tf2_msgs")
        snap = Snapshot(
            time_s=now,
            url=self.params.url,
            connection=c.state,
            connection_error=c.error,
            attempts=c.attempts,
            reconnects=c.reconnects,
            mode=self.mode,
            last_reset=last.get("reset"),
            resets=self._resets,
            failsafes=self._failsafes,
            last_failsafe=last.get("failsafe"),
            rearmed_since_reset=self._rearmed_since_reset,
            feedback_hz=rate,
            refused=self.refusals.total,
            last_refusal=self.refusals.last,
            tf=tf,
            extra=tuple(s.report(self.diagnostics.node_name) for s in self.sensors),
        )
        if robot is None:
            return snap
        board = c.board
        try:
            state = robot.state
            commanding = self.driver is not None
            return dataclasses.replace(
                snap,
                feedback_age_s=robot.feedback_age_s,
                feedback_expected_s=feedback_expected_s(state, self.lockstep, commanding, self.params.odom_rate),
                identity=robot.identity,
                state=state,
                failsafe=robot.failsafe,
                host=robot.stats,
                board=board[0] if board else None,
                board_time_s=board[1] if board else None,
                mismatches=tuple(str(m) for m in robot.mismatches),
            )
        except RoverLinkError:  # closed meanwhile
            return snap

    def _publish_diagnostics(self) -> None:
        msg = DiagnosticArray()
        msg.header.stamp = self.get_clock().now().to_msg()
        for report in self.diagnostics.build(self.snapshot()):
            status = DiagnosticStatus(
                level=bytes([report.level]),
                name=report.name,
                message=report.message,
                hardware_id=report.hardware_id,
                values=[KeyValue(key=k, value=v) for k, v in report.values],
            )
            msg.status.append(status)
        self.diag_pub.publish(msg)

    # -- shutting down -----------------------------------------------------------------------------
    def close(self) -> None:
        """Stop, disarm and close the robot (SIGINT, SIGTERM)."""
        for sensor in self.sensors:
            sensor.close()
        robot = self.connection.stop()
        with self._driver_lock:
            self.driver = None
        if robot is not None:
            for step in (robot.stop, robot.disarm):
                try:
                    step()
                except RoverLinkError as exc:
                    self.get_logger().warning(f"{step.__name__} on shutdown: {exc}")
            robot.close()
            self.get_logger().info("robot stopped, disarmed and closed")
        for name in ("host_sdk", MISMATCH_LOGGER, "roverlink.ros2"):
            logging.getLogger(name).removeHandler(self._log_handler)
