"""`Settings`, the part of a Robot that configures: the board's CONFIG, PID gains and turn signals.

A change is a read-modify-write of the board's whole CONFIG (or one wheel's gains): the calls
here do it as one step under a lock of their own, so concurrent changes to different fields all
stick, and changes to one field end with one of the values written.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable
from typing import Any

import numpy as np

from host_sdk import checks, lights
from host_sdk.errors import CommandRangeError, EncodeError, RoverLinkError, UnsupportedError
from host_sdk.lights import LightsStatus
from host_sdk.robot.gains_watch import GainsWatch, warn_about_gains
from host_sdk.robot.link import Link
from host_sdk.session import FeedbackSample, PidGains, RobotConfig
from protocol.codec.message import Message
from protocol.generated.constants import CONTROL_RATE_HZ, PID_ALL_WHEELS
from protocol.generated.enums import Capability, LightsMode
from protocol.generated.messages import (
    Config,
    GetConfig,
    GetLights,
    GetLinkStats,
    GetPid,
    LightsState,
    LinkStats,
    Pid,
    SaveConfig,
    SetConfig,
    SetPid,
)

CONFIG_FIELDS = tuple(f.name for f in SetConfig.FIELDS)
_GAINS = {f.name: f for f in SetPid.FIELDS if f.name != "wheel"}


class Settings:
    """Owns the read-modify-write lock and the watch on the latest gains; `configured` is called
    after the configuration changed (the robot refreshes kinematics it took from it)."""

    def __init__(self, link: Link, configured: Callable[[], None]) -> None:
        self._link = link
        self._configured = configured
        self._rmw = threading.RLock()  # one configuration read-modify-write at a time
        self._unwatch_gains: Callable[[], None] | None = None

    def _request(self, msg: Message) -> Message:
        return self._link.request(msg)

    # == configuration =============================================================================
    def read_config(self) -> RobotConfig:
        """Fetch the configuration from the board (GET_CONFIG)."""
        reply = self._request(GetConfig())
        assert isinstance(reply, Config)
        return self._link.config()

    def set_config(self, /, **changes: Any) -> RobotConfig:
        """Change configuration fields (names as in docs/protocol.md CONFIG), e.g.
        `robot.set_config(max_wheel_speed_mm_s=400, safe_state=SafeState.RAMP_DOWN)`.

        Reads the configuration, replaces the fields, sends SET_CONFIG (reliable: applied once) and
        reads it back, as one step: a concurrent set_config or set_pid waits for it. Raises
        CommandRangeError for an unknown field or a value outside its range, NackError when the
        board refuses (its `field` names the field)."""
        for key, value in changes.items():
            if key not in CONFIG_FIELDS:
                raise CommandRangeError(key, value, f"a CONFIG field: one of {', '.join(CONFIG_FIELDS)}")
        _config_with(self._link.config(), changes)  # every value checked before anything is sent
        with self._rmw:
            wanted = _config_with(self.read_config(), changes)
            self._request(SetConfig(**wanted.fields()))
            after = self.read_config()
            if after != wanted:
                raise RoverLinkError(f"the board's configuration read back differs from what was set: {after}")
            self._configured()
        return after

    def _wheels(self) -> int:
        identity = self._link.identity()
        return 2 if identity.capabilities & Capability.DIFF_DRIVE else 1

    def pid(self, wheel: int = 0) -> PidGains:
        """The velocity PID gains of one wheel (GET_PID)."""
        checks.integer("wheel", wheel, 0, self._wheels() - 1, what="a wheel index")
        reply = self._request(GetPid(wheel=wheel))
        assert isinstance(reply, Pid)
        gains = (reply.kp, reply.ki, reply.kd, reply.kf, reply.ks)
        # The board keeps f32: 0.62 comes back as 0.6200000047683716. The shortest decimal that is the
        # same f32 reads as it was set, and sent back it is the same gain.
        return PidGains(*(float(str(np.float32(g))) for g in gains))

    def set_pid(
        self,
        *,
        kp: float | None = None,
        ki: float | None = None,
        kd: float | None = None,
        kf: float | None = None,
        ks: float | None = None,
        wheel: int | None = None,
    ) -> PidGains:
        """Change PID gains of one wheel, or every wheel (wheel=None); unnamed gains keep each wheel's
        value. Takes effect at the board's next tick (its integrator is reset). Returns the gains
        read back (of `wheel`, or wheel 0). Like set_config, one read-modify-write at a time."""
        wheels = self._wheels()
        checks.optional(checks.integer, "wheel", wheel, 0, wheels - 1, what="a wheel index (None: every wheel)")
        named = {"kp": kp, "ki": ki, "kd": kd, "kf": kf, "ks": ks}
        given = {
            name: checks.number(name, value, _GAINS[name].lo, _GAINS[name].hi, unit=_GAINS[name].unit)
            for name, value in named.items()
            if value is not None
        }
        with self._rmw:
            if wheel is None and len(given) == len(_GAINS):
                self._request(SetPid(wheel=PID_ALL_WHEELS, **given))
            else:
                for w in range(wheels) if wheel is None else (wheel,):
                    gains = dataclasses.replace(self.pid(w), **given)
                    self._request(SetPid(wheel=w, **dataclasses.asdict(gains)))
            result = self.pid(wheel or 0)
        self._watch_gains(result)
        return result

    def _watch_gains(self, gains: PidGains) -> None:
        """Watch the driving that follows new gains; warn when they make a wheel oscillate."""
        if self._unwatch_gains is not None:
            self._unwatch_gains()  # the gains it watched are gone
        text = ", ".join(f"{name}={getattr(gains, name):g}" for name in _GAINS)
        watch = GainsWatch(text, warn_about_gains)

        def feed(sample: FeedbackSample) -> None:
            watch.feed(sample)
            if watch.finished:
                unsubscribe()

        self._unwatch_gains = unsubscribe = self._link.callbacks.subscribe("feedback", feed)

    def save_config(self) -> None:
        """Write configuration and PID gains to the board's EEPROM (refused while armed: disarm first)."""
        self._request(SaveConfig())

    # == turn signals ==============================================================================
    def set_lights(
        self,
        mode: LightsMode | str | None = None,
        *,
        steady: object = None,
        slow: object = None,
        fast: object = None,
    ) -> LightsStatus:
        """Choose the turn signals' behaviour (SET_LIGHTS), then read them back (GET_LIGHTS).

        `mode` is "auto" (the firmware's patterns from the motion state, as at power-up), "off" or
        "manual" (or a LightsMode); in manual, `steady`, `slow` (1.5 Hz) and `fast` (3 Hz) are lamp
        sets: Lights bits, 0..15, or names ("left", ["front_left", "rear_right"], "front,rear").
        Lamps given without a mode mean manual: `robot.set_lights(slow="left")`. FAILSAFE shows all
        four blinking fast whatever the mode; a new session (HELLO) or a reset brings back the robot
        file's power-up mode. Raises CommandRangeError for a bad argument, UnsupportedError
        (capability TURN_SIGNALS) on a robot without turn signals."""
        wanted = lights.request(mode, steady=steady, slow=slow, fast=fast)
        self._need_turn_signals("set_lights")
        self._request(wanted)
        # The board applies it at its next control tick: read back after that tick, so `lit`
        # shows the new mode's lamps, not the old one's.
        runner = self._link.runner
        runner.wait(lambda: runner.closed, 1.0 / CONTROL_RATE_HZ)
        return self.lights()

    def lights(self) -> LightsStatus:
        """The turn signals as the board has them (GET_LIGHTS): mode, masks and the lamps lit now.
        UnsupportedError (capability TURN_SIGNALS) on a robot without turn signals."""
        self._need_turn_signals("lights")
        reply = self._request(GetLights())
        assert isinstance(reply, LightsState)
        return LightsStatus.of(reply)

    def _need_turn_signals(self, call: str) -> None:
        identity = self._link.identity()
        if not identity.capabilities & Capability.TURN_SIGNALS:
            raise UnsupportedError(
                f"{call}(): {identity.robot_name or 'this robot'} has no turn signals (its firmware lacks "
                "the TURN_SIGNALS capability: a robot file gives it with the four LED pins of [lights])",
                Capability.TURN_SIGNALS,
            )

    def board_link_stats(self) -> LinkStats:
        """The firmware's own link counters (GET_LINK_STATS): what the board received and sent."""
        reply = self._request(GetLinkStats())
        assert isinstance(reply, LinkStats)
        return reply


def _config_with(config: RobotConfig, changes: dict[str, Any]) -> RobotConfig:
    """`config` with `changes`; CommandRangeError names a value outside its field's range."""
    wanted = dataclasses.replace(config, **changes)
    try:
        wanted.pack()
    except EncodeError as exc:
        raise CommandRangeError(exc.field, exc.value, exc.allowed) from None
    return wanted
