"""Running a conformance scenario on a backend, and the Python emulator's run of it as the reference."""

from __future__ import annotations

import dataclasses
import functools

from conformance_backends import Backend, Host, make_backend, on_board
from conformance_board_scenarios import (
    sc_config_fallback,
    sc_duplicate_arm,
    sc_encoder_fault,
    sc_esc_arming,
    sc_host_lights,
    sc_host_lights_unsupported,
    sc_leds,
    sc_no_storage,
    sc_save_config,
)
from conformance_scenarios import (
    TURNS_MM_S,
    sc_arm_and_refusals,
    sc_boot,
    sc_drive,
    sc_failsafe,
    sc_handshake,
    sc_lockstep,
    sc_lockstep_disarmed,
    sc_lockstep_queue,
    sc_reliable_config,
    sc_reset_mid_session,
    sc_stream_latest_wins,
    sc_turn_then_straight,
)
from conformance_square import sc_square

from emulator.firmware.config import IMAGE_ADDR, Gains, encode_image
from protocol.generated.profiles import PROFILES

SCENARIOS = {
    "boot": sc_boot,
    "handshake": sc_handshake,
    "arm_and_refusals": sc_arm_and_refusals,
    "failsafe": sc_failsafe,
    "reset_mid_session": sc_reset_mid_session,
    "reliable_config": sc_reliable_config,
    "lockstep": sc_lockstep,
    "lockstep_disarmed": sc_lockstep_disarmed,
    "lockstep_queue": sc_lockstep_queue,
    "stream_latest_wins": sc_stream_latest_wins,
    "duplicate_arm": sc_duplicate_arm,
    "encoder_fault": sc_encoder_fault,
    "save_config": sc_save_config,
    "no_storage": sc_no_storage,
    "config_fallback:crc": sc_config_fallback,
    "config_fallback:invalid": sc_config_fallback,
    "esc_arming": sc_esc_arming,
    "leds": sc_leds,
    "host_lights": sc_host_lights,
    "host_lights_unsupported": sc_host_lights_unsupported,
    **{name: functools.partial(sc_turn_then_straight, turn=turn) for name, turn in TURNS_MM_S.items()},
}
PROFILE = "diffdrive-tb6612"
SCENARIO_PROFILE = {"esc_arming": "picar", "host_lights_unsupported": "picar"}
"""Scenarios on another robot than PROFILE."""


def _image(**changes: object) -> bytes:
    """The EEPROM from address 0 as a board that saved `changes` over the defaults holds it: the
    boot counter (blank), then the config image (docs/firmware.md, EEPROM layout)."""
    robot = PROFILES[PROFILE]
    config = dataclasses.replace(robot.config, **changes)  # type: ignore[type-var]
    image = encode_image(config, [Gains.of(robot.pid)] * 2)
    return b"\xff" * IMAGE_ADDR + image


def _flip(image: bytes, at: int) -> bytes:
    return image[:at] + bytes([image[at] ^ 0x10]) + image[at + 1 :]


EEPROM_IMAGES = {
    # A saved image with one bit flipped in the config payload (accel_limit_mm_s2): CRC error.
    "config_fallback:crc": _flip(_image(accel_limit_mm_s2=1500), IMAGE_ADDR + 8),
    # A well-formed image (right CRC) whose values break a consistency rule: refused as a whole.
    "config_fallback:invalid": _image(steering_min_cdeg=9500),
}
"""Scenarios that boot on an EEPROM image other than a blank one."""
_reference: dict[tuple[str, str], dict[str, object]] = {}


def open_backend(backend_name: str, scenario: str, profile: str | None = None) -> Backend:
    """A fresh robot for `scenario`: its profile and its EEPROM image before the first boot."""
    return make_backend(
        backend_name, profile or SCENARIO_PROFILE.get(scenario, PROFILE), eeprom=EEPROM_IMAGES.get(scenario)
    )


def run(backend: Backend, name: str) -> dict[str, object]:
    h = Host(backend)
    if name.startswith("drive:"):
        return sc_drive(h, backend.profile)
    if name.startswith("square:"):
        return sc_square(h, backend.profile)
    return SCENARIOS[name](h)


def run_fresh(backend_name: str, name: str, profile: str | None = None) -> dict[str, object]:
    b = open_backend(backend_name, name, profile)
    try:
        return run(b, name)
    finally:
        b.close()


def reference(name: str, profile: str | None = None, backend: str = "python") -> dict[str, object]:
    """The Python model's run of scenario `name`, on the robot `backend` runs it on (a reference
    robot, or for rp2040 that robot moved to a Pico)."""
    robot = on_board(backend, profile or SCENARIO_PROFILE.get(name, PROFILE))
    key = (name, robot)
    if key not in _reference:
        _reference[key] = run_fresh("python", name, robot)
    return _reference[key]
