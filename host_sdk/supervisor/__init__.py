"""Riding through the robot's failures: `Supervisor` owns a robot's lifetime and turns a cut link, a
board reset, a failsafe or an unanswered request into state (`Health`) a program shows; a lost
port is opened again with backoff (`Connection`). An application layer over the SDK's core: it
uses `Robot` only, and `import host_sdk` does not load it (docs/sdk.md, "Riding through failures").
"""

from host_sdk.supervisor.connection import Connection
from host_sdk.supervisor.health import Banner, BoardReset, Health, Refusal
from host_sdk.supervisor.supervisor import LOST_AFTER_S, Supervisor

__all__ = ["LOST_AFTER_S", "Banner", "BoardReset", "Connection", "Health", "Refusal", "Supervisor"]
