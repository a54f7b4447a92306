"""Follow a target with the camera while avoiding obstacles with the lidar: a whole robot program.

On the emulator (a PiCar in a random room, on the emulator's virtual clock: as fast as the CPU allows):

    .venv/bin/python examples/follow.py --url 'emu://picar?world=random:1&lidar=ydlidar-f4&imu=jy901&camera=320x240&clock=virtual'

On a robot (the board, the lidar and the camera; `--imu` adds the JY901's gyro to the odometry):

    .venv/bin/python examples/follow.py --url /dev/ttyACM0 --profile picar --lidar /dev/ttyUSB0 \\
        --camera 0 --template target.png

Your own robot: `--robot my.toml` (docs/robot-file.md) in place of --profile; the board is checked
against the file and the footprint, camera and lidar are the file's (as on `emu://?robot=my.toml&...`).

An emulated robot with a camera serves a photo of its world's target (`endpoints["target"]`); on a
robot, `--template` is your photo of what to follow. It runs for `--duration` seconds (30). Only
`host_sdk` is imported: docs/autonomy.md.

Once a second it prints what the follower does (waiting: for the first frame; search: looking for
the target; track: following it; avoid: following round an obstacle; yield: getting out of the
target's way; stop: standing, at its distance or with no way to go; recover: backing out) and where
the robot is. It arms at the start and rides through the robot's failures (a line says what is
wrong): after a failsafe or a board reset the robot stays disarmed, unless `--rearm` asks for it to
be armed again.
"""

import argparse

from host_sdk.autonomy import ControlLoop, FollowPilot
from host_sdk.geometry import description_of, mount, profile_of, robot_geometry, sensor_mounts
from host_sdk.perception.template import read_template
from host_sdk.sensors import CameraSource, Jy901, Lidar
from host_sdk.supervisor import Supervisor

p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
for option in ("--url", "--profile", "--robot", "--lidar", "--camera", "--imu", "--template"):
    p.add_argument(option)
p.add_argument("--duration", type=float, default=30.0, help="seconds (default 30)")
p.add_argument("--rearm", action="store_true", help="arm again by itself after a failsafe or a board reset")
args = p.parse_args()

with Supervisor.connect(args.url, profile=args.profile, robot=args.robot, clamp=True) as sup:
    robot = sup.robot
    ports = robot.transport.endpoints  # an emu:// robot's own sensors (empty on a board)
    if description_of(robot) is not None:  # a robot file: its lidar
        model = sensor_mounts(robot, ["lidar"])["lidar"].device
    else:
        model = mount(args.profile or profile_of(robot) or "picar", "lidar").device
    lidar = Lidar.open(args.lidar or ports["lidar"], model)
    camera = CameraSource(int(args.camera) if (args.camera or "").isdigit() else args.camera or ports["camera"])
    imu = Jy901.open(args.imu or ports["imu"]) if args.imu or "imu" in ports else None
    photo = read_template(args.template) if args.template else CameraSource(ports["target"]).read().image
    pilot = FollowPilot.for_robot(robot_geometry(robot, args.profile), photo)
    if args.rearm:
        print("--rearm: the robot is armed again by itself after a failsafe or a board reset")
    with ControlLoop(sup, pilot, lidar=lidar, camera=camera, imu=imu, arm=True, rearm=args.rearm) as loop:
        shown = 0.0
        while (t := sup.now() - loop.started_s) < args.duration:
            step = loop.step()
            if t >= shown:  # once a second: what it does and where it is, and what is wrong
                shown += 1.0
                print(f"{t:5.1f} s  {step.mode:8s} x {step.pose.x_m:5.2f} m  y {step.pose.y_m:5.2f} m")
                if (banner := step.health.banner()) is not None:
                    # A failsafe met while driving, with what the lidar saw at the footprint then.
                    text = loop.last_failsafe if step.health.failsafe and loop.last_failsafe else banner.text
                    stays = not args.rearm and not step.health.armed  # nothing here arms it again
                    hint = "disarmed: run it again, or with --rearm" if stays else banner.hint
                    print(f"        {text}; {hint}")
            loop.wait()
    for device in (lidar, camera, imu):
        if device is not None:
            device.close()
