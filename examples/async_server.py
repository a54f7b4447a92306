"""Drive a slow square while serving the robot's odometry as JSON over HTTP: an asyncio robot program.

.venv/bin/python examples/async_server.py                                          # the emulated car, wall clock
.venv/bin/python examples/async_server.py "emu://diffdrive-tb6612?clock=virtual" --port 0  # virtual clock: CPU speed
.venv/bin/python examples/async_server.py /dev/ttyACM0 --seconds 120               # a real board

and meanwhile, from another terminal: curl http://127.0.0.1:8080/odometry

One event loop runs both: the control loop (`async for sample in robot.feedback()`: a command on
every FEEDBACK) and a tiny HTTP server (stdlib asyncio streams) on 127.0.0.1. While the control
loop awaits the robot, the server answers; on the emulator's virtual clock that await is what moves
the emulator's time. `--port 0` takes any free port; the first line printed names the URL.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import math

from host_sdk import AsyncRobot

SPEED_M_S = 0.2
SIDE_S = 2.5  # 0.5 m sides
TURN_RAD_S = 0.6  # rounded corners, so an Ackermann robot drives the same square
CORNER_S = (math.pi / 2) / TURN_RAD_S


def odometry_json(robot: AsyncRobot) -> bytes:
    p = robot.odometry.pose
    fields = {
        "x_m": p.x_m,
        "y_m": p.y_m,
        "theta_rad": p.theta_rad,
        "linear_m_s": p.linear_m_s,
        "angular_rad_s": p.angular_rad_s,
        "time_s": robot.now(),
        "state": robot.state,
    }
    return json.dumps(fields).encode()


async def serve(robot: AsyncRobot, port: int) -> asyncio.Server:
    """GET /odometry (or /): the pose as JSON; anything else: 404."""

    async def answer(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        try:
            request = (await reader.readline()).split()
            while (await reader.readline()).strip():  # the headers: not needed
                pass
            path = request[1] if len(request) > 1 else b""
            status, body = (
                ("200 OK", odometry_json(robot)) if path in (b"/", b"/odometry") else ("404 Not Found", b"{}")
            )
            head = f"HTTP/1.1 {status}\r\nContent-Type: application/json\r\nContent-Length: {len(body)}\r\n"
            writer.write(head.encode() + b"Connection: close\r\n\r\n" + body)
            await writer.drain()
        except ConnectionError:
            pass  # the client left
        finally:
            writer.close()

    return await asyncio.start_server(answer, "127.0.0.1", port)


async def drive_square(robot: AsyncRobot, seconds: float) -> None:
    """Sides and corners by the robot's clock, a command on every FEEDBACK (renewed, so it stays live)."""
    await robot.arm()
    robot.odometry.reset()
    start = shown = robot.now()
    async for _ in robot.feedback():
        t = robot.now() - start
        if t >= seconds:
            break
        corner = t % (SIDE_S + CORNER_S) >= SIDE_S
        robot.drive(SPEED_M_S, TURN_RAD_S if corner else 0.0, clamp=True)
        if robot.now() - shown >= 1.0:
            shown = robot.now()
            print(f"t={t:5.1f} s  {odometry_json(robot).decode()}", flush=True)
    robot.stop()


async def run(url: str, seconds: float, port: int) -> None:
    async with AsyncRobot.connect(url) as robot, await serve(robot, port) as server:
        host, bound = server.sockets[0].getsockname()[:2]
        print(f"serving http://{host}:{bound}/odometry", flush=True)
        await drive_square(robot, seconds)
        p = robot.odometry.pose
        print(f"done: x={p.x_m:+.3f} m y={p.y_m:+.3f} m heading={math.degrees(p.theta_rad):.1f} deg", flush=True)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("url", nargs="?", default="emu://", help="the robot (default: emu://, the emulator)")
    parser.add_argument("--port", type=int, default=8080, help="HTTP port on 127.0.0.1 (0: any free one)")
    parser.add_argument("--seconds", type=float, default=60.0, help="how long to drive, robot clock (default 60)")
    args = parser.parse_args(argv)
    asyncio.run(run(args.url, args.seconds, args.port))


if __name__ == "__main__":
    main()
