"""The robot file's [emulator.*] keys (protocol/robotfile/schema.py, data below the emulator) are
the emulator's model parameters (emulator/plant/): every field a key, with the same default, but
for the ones the file says elsewhere (the gearbox, the pulses, the servo's travel and centre)."""

from __future__ import annotations

import dataclasses

import pytest

from emulator.plant.esc import EscParams
from emulator.plant.motor import MotorParams
from emulator.plant.servo import ServoParams
from emulator.plant.vehicle import BodyParams
from protocol.robotfile.schema import ABSENT, REQUIRED, SECTIONS

ELSEWHERE = {
    "motor": {"gear_ratio"},  # [geometry] gear_ratio
    "body": set(),
    "esc": {"min_us", "max_us", "nominal_neutral_us"},  # [esc]
    "servo": {"min_us", "max_us", "travel_min_deg", "travel_max_deg", "straight_deg"},  # [steering]
}
ONLY_IN_THE_FILE = {"servo": {"travel_margin_deg"}}
MODELS: dict[str, type] = {"motor": MotorParams, "body": BodyParams, "esc": EscParams, "servo": ServoParams}


@pytest.mark.parametrize("part", sorted(MODELS))
def test_every_model_parameter_is_a_key_with_its_default(part: str) -> None:
    fields = {f.name: f for f in dataclasses.fields(MODELS[part]) if f.name not in ELSEWHERE[part]}
    keys = {k.name: k for k in SECTIONS[f"emulator.{part}"] if k.name not in ONLY_IN_THE_FILE.get(part, set())}
    assert set(keys) == set(fields)
    for name, key in keys.items():
        default = fields[name].default
        if default is dataclasses.MISSING:
            assert key.default is REQUIRED, name
        elif default == float("inf"):
            assert key.default is ABSENT, name  # absent: no limit
        else:
            assert key.default == default, name
