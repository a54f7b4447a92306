"""A robot program with the web console: watch the camera, scan and pose in a browser, draw the
target, follow it, drive, arm and stop (docs/console.md).

On the emulator (a PiCar in a random room, on the wall clock so a person can drive it):

    python examples/console.py --url 'emu://picar?world=random:3&lidar=ydlidar-f4&camera=320x240'

On a robot, opened from a laptop on the same network (it prints the URLs, the robot's name among
them, each with the token):

    python examples/console.py --url /dev/ttyACM0 --profile picar --lidar /dev/ttyUSB0 --camera 0 --host 0.0.0.0

It runs until Ctrl-C or for `--duration` seconds. Only `host_sdk` is imported (the `console` extra).
"""

import argparse

from host_sdk import Robot
from host_sdk.autonomy import ControlLoop
from host_sdk.console import Console
from host_sdk.geometry import mount, profile_of, robot_geometry
from host_sdk.sensors import CameraSource, Lidar

p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
for option in ("--url", "--profile", "--lidar", "--camera"):
    p.add_argument(option)
p.add_argument("--host", default="127.0.0.1", help="address to serve on (default 127.0.0.1: this machine only)")
p.add_argument("--port", type=int, default=8080, help="TCP port (default 8080; 0: any free one)")
p.add_argument("--duration", type=float, help="seconds (default: until Ctrl-C)")
args = p.parse_args()

with Robot.connect(args.url, profile=args.profile, clamp=True) as robot:
    ports = robot.transport.endpoints  # an emu:// robot's own sensors (empty on a board)
    if not (args.lidar or "lidar" in ports) or not (args.camera or "camera" in ports):
        raise SystemExit("give --lidar and --camera (or an emu:// URL with lidar=... and camera=...)")
    model = mount(args.profile or profile_of(robot) or "picar", "lidar").device
    lidar = Lidar.open(args.lidar or ports["lidar"], model)
    camera = CameraSource(int(args.camera) if (args.camera or "").isdigit() else args.camera or ports["camera"])
    with Console(robot, robot_geometry(robot, args.profile), host=args.host, port=args.port) as console:
        print("open " + "  or  ".join(console.urls), flush=True)  # with --host 0.0.0.0: the robot's name too
        # rearm=False: only the page arms the robot (not the start, not a failsafe).
        with ControlLoop(robot, console.pilot, lidar=lidar, camera=camera, rearm=False) as loop:
            try:
                while args.duration is None or robot.now() - loop.started_s < args.duration:
                    loop.step()
                    loop.wait()
            except KeyboardInterrupt:
                pass
    lidar.close()
    camera.close()
