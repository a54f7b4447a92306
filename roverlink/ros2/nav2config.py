"""Nav2's parameters (ROS 2 Jazzy, nav2_bringup's navigation_launch.py) for a robot (roverlink.ros2.configs).

The controller is MPPI with the robot's motion model: DiffDrive, or Ackermann with the car's
tightest turn as min_turning_r; a car plans with Smac Hybrid-A* (Reeds-Shepp: it reverses) on the
same radius, a differential robot with NavFn. Footprint, speed and acceleration limits are the
robot file's; frames and topics the node's. Parameter types matter to Nav2 (a double given as 1
fails), so every double here is a float.
"""

from __future__ import annotations

from typing import Any

from roverlink.ros2.params import BY_NAME
from roverlink.ros2.robotfacts import MAP_FRAME, TOPICS, RobotFacts, frame

COLLISION_MONITOR_IN = "cmd_vel_smoothed"
"""navigation_launch.py: controller -> cmd_vel_nav -> velocity_smoother -> cmd_vel_smoothed ->
collision_monitor -> cmd_vel (the node's)."""
INFLATION_MARGIN_M = 0.25
"""Inflation beyond the robot's circumscribed radius: the planner keeps this far off walls."""


def _stamped() -> bool:
    value = BY_NAME["use_stamped_vel"].default
    assert isinstance(value, bool)
    return value


def _body(facts: RobotFacts) -> dict[str, Any]:
    if facts.footprint:
        points = ", ".join(f"[{x:g}, {y:g}]" for x, y in facts.footprint)
        return {"footprint": f"[{points}]"}
    return {"robot_radius": facts.robot_radius_m}


def _obstacles(facts: RobotFacts) -> dict[str, Any]:
    low, high = facts.lidar_range_m
    return {
        "plugin": "nav2_costmap_2d::ObstacleLayer",
        "enabled": True,
        "observation_sources": "scan",
        "scan": {
            "topic": TOPICS["scan"],
            "data_type": "LaserScan",
            "marking": True,
            "clearing": True,
            "max_obstacle_height": 2.0,
            "raytrace_min_range": low,
            "raytrace_max_range": min(high, 6.0),
            "obstacle_min_range": low,
            "obstacle_max_range": min(high, 5.0),
        },
    }


def _costmap(facts: RobotFacts, local: bool) -> dict[str, Any]:
    common: dict[str, Any] = {
        "update_frequency": 5.0 if local else 1.0,
        "publish_frequency": 2.0 if local else 1.0,
        "global_frame": frame("odom_frame") if local else MAP_FRAME,
        "robot_base_frame": frame("base_frame"),
        "resolution": 0.05,
        **_body(facts),
    }
    inflation = {
        "plugin": "nav2_costmap_2d::InflationLayer",
        "cost_scaling_factor": 3.0,
        "inflation_radius": round(facts.robot_radius_m + INFLATION_MARGIN_M, 3),
    }
    if local:
        common |= {"rolling_window": True, "width": 3, "height": 3}
        layers: dict[str, Any] = {"obstacle_layer": _obstacles(facts), "inflation_layer": inflation}
    else:
        common["track_unknown_space"] = True
        static = {"plugin": "nav2_costmap_2d::StaticLayer", "map_subscribe_transient_local": True}
        layers = {"static_layer": static, "obstacle_layer": _obstacles(facts), "inflation_layer": inflation}
    params = {**common, "plugins": list(layers), **layers, "always_send_full_costmap": True}
    name = "local_costmap" if local else "global_costmap"
    return {name: {name: {"ros__parameters": params}}}


def _critics(facts: RobotFacts) -> dict[str, Any]:
    critics: dict[str, Any] = {
        "ConstraintCritic": {"enabled": True, "cost_power": 1, "cost_weight": 4.0},
        "CostCritic": {
            "enabled": True,
            "cost_power": 1,
            "cost_weight": 3.81,
            "critical_cost": 300.0,
            "consider_footprint": bool(facts.footprint),
            "collision_cost": 1000000.0,
            "near_goal_distance": 1.0,
            "trajectory_point_step": 2,
        },
        "GoalCritic": {"enabled": True, "cost_power": 1, "cost_weight": 5.0, "threshold_to_consider": 1.4},
        "GoalAngleCritic": {"enabled": True, "cost_power": 1, "cost_weight": 3.0, "threshold_to_consider": 0.5},
        "PathAlignCritic": {
            "enabled": True,
            "cost_power": 1,
            "cost_weight": 14.0,
            "max_path_occupancy_ratio": 0.05,
            "trajectory_point_step": 4,
            "threshold_to_consider": 0.5,
            "offset_from_furthest": 20,
            "use_path_orientations": False,
        },
        "PathFollowCritic": {"enabled": True, "cost_power": 1, "cost_weight": 5.0, "threshold_to_consider": 1.4},
        "PathAngleCritic": {
            "enabled": True,
            "cost_power": 1,
            "cost_weight": 2.0,
            "offset_from_furthest": 4,
            "threshold_to_consider": 0.5,
            "max_angle_to_furthest": 1.0,
            # A car reverses along the path where it must (Reeds-Shepp); a differential robot turns.
            "mode": 2 if facts.ackermann else 0,
        },
        "PreferForwardCritic": {"enabled": True, "cost_power": 1, "cost_weight": 5.0, "threshold_to_consider": 0.5},
    }
    return {"critics": list(critics), **critics}


def _mppi(facts: RobotFacts) -> dict[str, Any]:
    v, w = facts.max_speed_m_s, facts.max_yaw_rate
    params: dict[str, Any] = {
        "plugin": "nav2_mppi_controller::MPPIController",
        # Fewer samples than Nav2's example: a Raspberry Pi's four cores at 20 Hz.
        "time_steps": 56,
        "model_dt": 0.05,
        "batch_size": 1000,
        "iteration_count": 1,
        "vx_std": 0.2,
        "wz_std": 0.4,
        "vx_max": v,
        "vx_min": -v / 2,
        "wz_max": w,
        "ax_max": facts.accel_m_s2,
        "ax_min": -facts.decel_m_s2,
        "az_max": facts.yaw_accel,
        "prune_distance": 1.7,
        "transform_tolerance": 0.1,
        "temperature": 0.3,
        "gamma": 0.015,
        "motion_model": "Ackermann" if facts.ackermann else "DiffDrive",
        "visualize": False,
        "regenerate_noises": True,
    }
    if facts.ackermann:
        params["AckermannConstraints"] = {"min_turning_r": facts.min_turning_radius_m}
    return params | _critics(facts)


def _controller(facts: RobotFacts) -> dict[str, Any]:
    return {
        "controller_frequency": 20.0,
        "costmap_update_timeout": 0.3,
        "min_x_velocity_threshold": 0.001,
        "min_y_velocity_threshold": 0.5,
        "min_theta_velocity_threshold": 0.001,
        "failure_tolerance": 0.3,
        "enable_stamped_cmd_vel": _stamped(),
        "progress_checker_plugins": ["progress_checker"],
        "goal_checker_plugins": ["general_goal_checker"],
        "controller_plugins": ["FollowPath"],
        "progress_checker": {
            "plugin": "nav2_controller::SimpleProgressChecker",
            "required_movement_radius": 0.5,
            "movement_time_allowance": 10.0,
        },
        "general_goal_checker": {
            "plugin": "nav2_controller::SimpleGoalChecker",
            "stateful": True,
            "xy_goal_tolerance": 0.25,
            # A car reaches a heading only by driving: it gets a wider tolerance.
            "yaw_goal_tolerance": 0.5 if facts.ackermann else 0.25,
        },
        "FollowPath": _mppi(facts),
    }


def _planner(facts: RobotFacts) -> dict[str, Any]:
    if facts.ackermann:
        grid: dict[str, Any] = {
            "plugin": "nav2_smac_planner::SmacPlannerHybrid",
            "motion_model_for_search": "REEDS_SHEPP",
            "minimum_turning_radius": facts.min_turning_radius_m,
            "allow_unknown": True,
            "tolerance": 0.25,
            "max_planning_time": 5.0,
            "angle_quantization_bins": 72,
            "reverse_penalty": 2.0,
            "smooth_path": True,
        }
    else:
        grid = {
            "plugin": "nav2_navfn_planner::NavfnPlanner",
            "tolerance": 0.5,
            "use_astar": False,
            "allow_unknown": True,
        }
    return {
        "expected_planner_frequency": 20.0,
        "costmap_update_timeout": 1.0,
        "planner_plugins": ["GridBased"],
        "GridBased": grid,
    }


def _behaviors(facts: RobotFacts) -> dict[str, Any]:
    plugins = {
        "spin": "nav2_behaviors::Spin",
        "backup": "nav2_behaviors::BackUp",
        "drive_on_heading": "nav2_behaviors::DriveOnHeading",
        "assisted_teleop": "nav2_behaviors::AssistedTeleop",
        "wait": "nav2_behaviors::Wait",
    }
    return {
        "local_costmap_topic": "local_costmap/costmap_raw",
        "global_costmap_topic": "global_costmap/costmap_raw",
        "local_footprint_topic": "local_costmap/published_footprint",
        "global_footprint_topic": "global_costmap/published_footprint",
        "cycle_frequency": 10.0,
        "enable_stamped_cmd_vel": _stamped(),
        "behavior_plugins": list(plugins),
        **{name: {"plugin": plugin} for name, plugin in plugins.items()},
        "local_frame": frame("odom_frame"),
        "global_frame": MAP_FRAME,
        "robot_base_frame": frame("base_frame"),
        "transform_tolerance": 0.1,
        "simulate_ahead_time": 2.0,
        "max_rotational_vel": facts.max_yaw_rate,
        "min_rotational_vel": min(0.4, facts.max_yaw_rate),
        "rotational_acc_lim": facts.yaw_accel,
    }


def _velocity_smoother(facts: RobotFacts, odom_topic: str) -> dict[str, Any]:
    v, w = facts.max_speed_m_s, facts.max_yaw_rate
    return {
        "smoothing_frequency": 20.0,
        "scale_velocities": False,
        "feedback": "OPEN_LOOP",
        "enable_stamped_cmd_vel": _stamped(),
        "max_velocity": [v, 0.0, w],
        "min_velocity": [-v, 0.0, -w],
        "max_accel": [facts.accel_m_s2, 0.0, facts.yaw_accel],
        "max_decel": [-facts.decel_m_s2, 0.0, -facts.yaw_accel],
        "odom_topic": odom_topic,
        "odom_duration": 0.1,
        "deadband_velocity": [0.0, 0.0, 0.0],
        "velocity_timeout": 1.0,
    }


def _collision_monitor() -> dict[str, Any]:
    return {
        "base_frame_id": frame("base_frame"),
        "odom_frame_id": frame("odom_frame"),
        "cmd_vel_in_topic": COLLISION_MONITOR_IN,
        "cmd_vel_out_topic": TOPICS["cmd_vel"],
        "enable_stamped_cmd_vel": _stamped(),
        "state_topic": "collision_monitor_state",
        "transform_tolerance": 0.2,
        "source_timeout": 1.0,
        "base_shift_correction": True,
        "stop_pub_timeout": 2.0,
        "polygons": ["FootprintApproach"],
        "FootprintApproach": {
            "type": "polygon",
            "action_type": "approach",
            "footprint_topic": "local_costmap/published_footprint",
            "time_before_collision": 1.2,
            "simulation_time_step": 0.1,
            "min_points": 6,
            "visualize": False,
            "enabled": True,
        },
        "observation_sources": ["scan"],
        "scan": {"type": "scan", "topic": TOPICS["scan"], "enabled": True},
    }


def _servers(odom_topic: str) -> dict[str, Any]:
    """The servers whose parameters do not depend on the robot but on the node's names."""
    base, odom = frame("base_frame"), frame("odom_frame")
    return {
        "bt_navigator": {
            "global_frame": MAP_FRAME,
            "robot_base_frame": base,
            "odom_topic": odom_topic,
            "bt_loop_duration": 10,
            "default_server_timeout": 20,
            "wait_for_service_timeout": 1000,
            "action_server_result_timeout": 900.0,
            "navigators": ["navigate_to_pose", "navigate_through_poses"],
            "navigate_to_pose": {"plugin": "nav2_bt_navigator::NavigateToPoseNavigator"},
            "navigate_through_poses": {"plugin": "nav2_bt_navigator::NavigateThroughPosesNavigator"},
        },
        "smoother_server": {
            "smoother_plugins": ["simple_smoother"],
            "simple_smoother": {
                "plugin": "nav2_smoother::SimpleSmoother",
                "tolerance": 1.0e-10,
                "max_its": 1000,
                "do_refinement": True,
            },
        },
        "waypoint_follower": {
            "loop_rate": 20,
            "stop_on_failure": False,
            "waypoint_task_executor_plugin": "wait_at_waypoint",
            "wait_at_waypoint": {
                "plugin": "nav2_waypoint_follower::WaitAtWaypoint",
                "enabled": True,
                "waypoint_pause_duration": 200,
            },
        },
        "route_server": {"route_frame": MAP_FRAME, "base_frame": base},
        # navigation_launch.py starts the docking server; it needs one dock plugin to configure.
        "docking_server": {
            "base_frame": base,
            "fixed_frame": odom,
            "enable_stamped_cmd_vel": _stamped(),
            "dock_plugins": ["simple_charging_dock"],
            "simple_charging_dock": {"plugin": "opennav_docking::SimpleChargingDock"},
        },
    }


def nav2_params(facts: RobotFacts, odom_topic: str = TOPICS["odom"]) -> dict[str, Any]:
    """Every node navigation_launch.py starts, configured for the robot; `odom_topic`: the node's
    odom, or an EKF's odometry/filtered."""
    nodes: dict[str, Any] = {
        "controller_server": _controller(facts),
        "planner_server": _planner(facts),
        "behavior_server": _behaviors(facts),
        "velocity_smoother": _velocity_smoother(facts, odom_topic),
        "collision_monitor": _collision_monitor(),
        **_servers(odom_topic),
    }
    out = {name: {"ros__parameters": params} for name, params in nodes.items()}
    return out | _costmap(facts, local=True) | _costmap(facts, local=False)
