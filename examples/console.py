"""A robot program with the web console: watch the camera, scan and pose in a browser, draw the
target, follow it, drive, arm and stop (docs/console.md).

On the emulator (a PiCar in a random room, on the wall clock so a person can drive it):

    .venv/bin/python examples/console.py --url 'emu://picar?world=random:3&lidar=ydlidar-f4&camera=320x240'

On a robot, opened from a laptop on the same network (it prints the URLs, the robot's name among
them, each with the token):

    .venv/bin/python examples/console.py --url /dev/ttyACM0 --profile picar --lidar /dev/ttyUSB0 \\
        --camera 0 --host 0.0.0.0

It rides through the robot's failures: a cut link, a board reset, a USB adapter pulled out and
plugged in again are shown on the page, the robot is reconnected by itself and waits for Arm.
Following lasts while the driving browser keeps it alive; `--autonomous` keeps it going with no
browser open. It runs until Ctrl-C or for `--duration` seconds. Only `host_sdk` is imported (the
`console` extra).
"""

import argparse

from host_sdk.autonomy import ControlLoop
from host_sdk.console import Console
from host_sdk.geometry import mount, profile_of, robot_geometry
from host_sdk.sensors import CameraSource, Lidar
from host_sdk.supervisor import Supervisor

p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
for option in ("--url", "--profile", "--lidar", "--camera"):
    p.add_argument(option)
p.add_argument("--host", default="127.0.0.1", help="address to serve on (default 127.0.0.1: this machine only)")
p.add_argument("--port", type=int, default=8080, help="TCP port (default 8080; 0: any free one)")
p.add_argument("--duration", type=float, help="seconds (default: until Ctrl-C)")
p.add_argument("--autonomous", action="store_true", help="keep following with no browser open")
args = p.parse_args()

# The supervisor owns the robot: its failures are shown, a lost port is opened again; it never arms.
with Supervisor.connect(args.url, profile=args.profile, clamp=True) as sup:
    robot = sup.robot
    ports = robot.transport.endpoints  # an emu:// robot's own sensors (empty on a board)
    if not (args.lidar or "lidar" in ports) or not (args.camera or "camera" in ports):
        raise SystemExit("give --lidar and --camera (or an emu:// URL with lidar=... and camera=...)")
    model = mount(args.profile or profile_of(robot) or "picar", "lidar").device
    lidar = Lidar.open(args.lidar or ports["lidar"], model)
    camera = CameraSource(int(args.camera) if (args.camera or "").isdigit() else args.camera or ports["camera"])
    geometry = robot_geometry(robot, args.profile)
    with Console(sup, geometry, host=args.host, port=args.port, autonomous=args.autonomous) as console:
        print("open " + "  or  ".join(console.urls), flush=True)  # with --host 0.0.0.0: the robot's name too
        if args.autonomous:
            print("--autonomous: following goes on with no browser open (STOP on the page or Ctrl-C stops it)")
        # Only the page arms the robot: not the start (arm=False), not after a failsafe (rearm=False).
        with ControlLoop(sup, console.pilot, lidar=lidar, camera=camera, arm=False, rearm=False) as loop:
            try:
                while args.duration is None or sup.now() - loop.started_s < args.duration:
                    loop.step()
                    loop.wait()
            except KeyboardInterrupt:
                pass
    lidar.close()
    camera.close()
