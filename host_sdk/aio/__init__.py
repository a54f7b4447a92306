"""asyncio support: `AsyncRobot` (host_sdk.aio.robot) and its `FeedbackStream` (host_sdk.aio.feedback)."""

from host_sdk.aio.feedback import DEFAULT_MAXSIZE, FeedbackStream
from host_sdk.aio.robot import VIRTUAL_SLICE_S, AsyncRobot, Connecting

__all__ = ["DEFAULT_MAXSIZE", "VIRTUAL_SLICE_S", "AsyncRobot", "Connecting", "FeedbackStream"]
