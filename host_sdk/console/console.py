"""The console object: its server and the pilot a robot program runs (see the package's docs)."""

from __future__ import annotations

import socket

from host_sdk.console.access import Access
from host_sdk.console.hub import Hub
from host_sdk.console.pilot import ConsolePilot
from host_sdk.console.server import ConsoleServer
from host_sdk.geometry import RobotGeometry
from host_sdk.perception.class_tracker import FrameTracker
from host_sdk.robot import Robot
from host_sdk.supervisor import Supervisor


class Console:
    """The console for `robot` (a `Supervisor`, or a Robot it supervises): its server (`host`,
    `port`; a `token` is needed off loopback and made if not given) and the pilot its control loop
    runs (`pilot`). `autonomous`: following goes on with no browser keeping it alive (say so to the
    user: the page shows it)."""

    def __init__(
        self,
        robot: Robot | Supervisor,
        geometry: RobotGeometry,
        *,
        host: str = "127.0.0.1",
        port: int = 8080,
        token: str | None = None,
        target_height_m: float | None = None,
        follow_gap_m: float | None = None,
        max_speed_m_s: float = 0.45,
        max_turn_rad_s: float = 2.0,
        jpeg_quality: int = 70,
        tracker: FrameTracker | None = None,
        autonomous: bool = False,
    ) -> None:
        self.supervisor = robot if isinstance(robot, Supervisor) else Supervisor(robot)
        self.access = Access.for_host(host, token)
        self.hub = Hub(command_lifetime_s=self.robot.watchdog_s, autonomous=autonomous)
        self.server = ConsoleServer(
            self.hub,
            self.access,
            port,
            on_stop=self.supervisor.stop,
            jpeg_quality=jpeg_quality,
            max_speed=(max_speed_m_s, max_turn_rad_s),
            on_dismiss=self.supervisor.dismiss,
        )
        self.pilot = ConsolePilot(
            self.hub,
            self.supervisor,
            geometry,
            target_height_m=target_height_m,
            follow_gap_m=follow_gap_m,
            max_speed_m_s=max_speed_m_s,
            tracker=tracker,
        )

    @property
    def robot(self) -> Robot:
        """The robot now (another object once a lost port was opened again)."""
        return self.supervisor.robot

    def start(self) -> str:
        """Listen; the URL to open (with the token, if one is needed)."""
        self.server.start()
        return self.url

    @property
    def url(self) -> str:
        """The URL to open on this machine (with the token, if one is needed)."""
        return self.access.url(self.server.port)

    @property
    def urls(self) -> list[str]:
        """This machine's URL, and listening on every address the robot's name on the network too
        (NAME.local and NAME, as the network may resolve either): what to print for a laptop."""
        found = [self.url]
        if self.access.host in ("0.0.0.0", "::"):
            name = socket.gethostname()
            found += [self.access.url(self.server.port, other) for other in (f"{name}.local", name)]
        return found

    def close(self) -> None:
        self.server.close()

    def __enter__(self) -> Console:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
