"""Generated files are deterministic, marked DO NOT EDIT, committed, and checked for drift."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

from protocol.__main__ import main
from protocol.generator import generate, hardware, hashing, loader, references
from protocol.generator.model import Spec

ROOT = generate.ROOT
GOOD = generate.SPEC.read_text(encoding="utf-8")


def spec(text: str = GOOD) -> Spec:
    return loader.parse(text, "protocol/spec/roverlink.toml")


def render(s: Spec) -> dict[str, str]:
    folder = generate.SPEC.parent
    contract = hardware.load(folder / "hardware.toml", ROOT, s)
    return generate.render(s, references.load(folder.parent / "robots", ROOT), contract)


def copy_spec(root: Path) -> None:
    """The spec, the hardware contract and the reference robots' files under `root`."""
    (root / "protocol" / "spec").mkdir(parents=True)
    for name in ("roverlink.toml", "hardware.toml"):
        shutil.copy(generate.SPEC.parent / name, root / "protocol" / "spec" / name)
    shutil.copytree(generate.SPEC.parent.parent / "robots", root / "protocol" / "robots")


def test_rendering_is_deterministic_and_free_of_paths_and_dates(tmp_path: Path) -> None:
    first = render(spec())
    # The same spec in another checkout renders to the same bytes.
    other = tmp_path / "elsewhere"
    copy_spec(other)
    second = generate.render(*generate.load(other / "protocol" / "spec" / "roverlink.toml", other))
    assert first == second
    for rel, text in first.items():
        assert str(ROOT) not in text, rel
        assert str(tmp_path) not in text, rel
        assert not re.search(r"\b20[0-9]{2}-[01][0-9]-[0-3][0-9]\b", text), f"{rel} holds a date"


def test_every_output_starts_with_do_not_edit_naming_the_spec_and_hash() -> None:
    s = spec()
    for rel, text in render(s).items():
        first, second = [*text.splitlines(), ""][:2]
        assert "DO NOT EDIT" in first and ("protocol/spec/" in first or "protocol/robots/" in first), rel
        # the hardware contract is not wire: no spec hash
        if "generated from protocol/spec/hardware.toml by" not in first:
            assert f"0x{s.spec_hash:08X}" in first + second, rel


def test_committed_outputs_match_the_spec() -> None:
    assert main(["check"]) == 0


def test_check_names_each_stale_file_and_says_how_to_fix(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    copy_spec(tmp_path)
    spec_file = tmp_path / "protocol" / "spec" / "roverlink.toml"
    assert main(["generate", "--spec", str(spec_file), "--root", str(tmp_path)]) == 0
    assert main(["check", "--spec", str(spec_file), "--root", str(tmp_path)]) == 0
    edited = tmp_path / "protocol" / "generated" / "constants.py"
    edited.write_text(edited.read_text() + "# hand edit\n")
    (tmp_path / "docs" / "protocol.md").unlink()
    capsys.readouterr()
    assert main(["check", "--spec", str(spec_file), "--root", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "stale: protocol/generated/constants.py" in err
    assert "stale: docs/protocol.md" in err
    assert "python -m protocol generate" in err
    # A spec change makes every file that embeds the hash stale.
    spec_file.write_text(GOOD.replace('value = 250\ndoc = "Watchdog period', 'value = 300\ndoc = "Watchdog period'))
    assert main(["check", "--spec", str(spec_file), "--root", str(tmp_path)]) == 1


def test_cpp_checks_take_enum_values_as_a_range_or_a_switch_when_they_have_gaps() -> None:
    """Contiguous enum values are a range test in the C++ is_valid_<Enum>(); with gaps, a switch."""
    header = "arduino/RoverLink/src/generated/roverlink_protocol.h"
    source = "arduino/RoverLink/src/generated/roverlink_protocol.cpp"
    files = render(spec())
    assert "inline bool is_valid_NackReason(uint8_t value) {\n    return value >= 1 && value <= 9;\n}" in files[header]
    assert "if (!is_valid_NackReason(static_cast<uint8_t>(m.reason))) return false;" in files[source]
    files = render(spec(GOOD.replace('{ name = "ARMED", value = 9,', '{ name = "ARMED", value = 12,')))
    cases = " ".join(f"case {v}:" for v in (1, 2, 3, 4, 5, 6, 7, 8, 12))
    assert f"switch (value) {{ {cases} return true; default: return false; }}" in files[header]
    assert "if (!is_valid_NackReason(static_cast<uint8_t>(m.reason))) return false;" in files[source]


def test_cpp_range_checks_leave_out_the_bounds_of_the_type() -> None:
    source = render(spec())["arduino/RoverLink/src/generated/roverlink_protocol.cpp"]
    assert "if (m.watchdog_ms < 50u || m.watchdog_ms > 2000u) return 0;" in source
    assert "if (m.encoder_cpr < 1u) return 6;" in source  # 1..65535
    assert "if (m.max_effort_permille > 1000u) return 5;" in source  # 0..1000
    assert "if (m.steering_mrad < -1571 || m.steering_mrad > 1571) return 1;" in source


def test_cpp_range_checks_loop_over_adjacent_fields_with_the_same_check() -> None:
    source = render(spec())["arduino/RoverLink/src/generated/roverlink_protocol.cpp"]
    # SET_PID's gains, fields 1..5, 0.0..1000.0: from -0.0's key (0x7FFFFFFF) to 1000.0's
    # (0x447A0000 with the sign bit set)
    set_pid = source[source.index("uint8_t check_ranges(const SetPid& m) {") :]
    set_pid = set_pid[: set_pid.index("\n}\n")]
    assert "for (uint8_t i = 0; i < 5; ++i) {" in set_pid
    assert "offsetof(SetPid, kp) + i * sizeof v" in set_pid
    assert "if (!layout::f32_within(v, 0x7FFFFFFFUL, 0xC47A0000UL)) return static_cast<uint8_t>(1 + i);" in set_pid
    # the accel and decel limits (fields 2, 3) share 1..65535; max_wheel_speed (4) has its own range
    assert "if (v < 1u) return static_cast<uint8_t>(2 + i);" in source
    assert "if (m.max_wheel_speed_mm_s < 1u || m.max_wheel_speed_mm_s > 20000u) return 4;" in source


def test_crc_extra_follows_the_definition_not_the_prose() -> None:
    base = spec().message("SET_WHEEL_SPEEDS")
    renamed = spec(GOOD.replace('name = "left_mm_s"', 'name = "left_speed_mm_s"')).message("SET_WHEEL_SPEEDS")
    retyped = spec(GOOD.replace('{ name = "left_mm_s", type = "i16"', '{ name = "left_mm_s", type = "i32"')).message(
        "SET_WHEEL_SPEEDS"
    )
    reworded = spec(GOOD.replace("Left wheel target speed", "Target speed of the left wheel")).message(
        "SET_WHEEL_SPEEDS"
    )
    assert renamed.crc_extra != base.crc_extra
    assert retyped.crc_extra != base.crc_extra
    assert reworded.crc_extra == base.crc_extra


def test_crc_extra_derivation_is_the_documented_one() -> None:
    m = spec().message("SET_WHEEL_SPEEDS")
    crc = hashing.crc16(b"SET_WHEEL_SPEEDS i16 left_mm_s i16 right_mm_s")
    assert m.crc_extra == (crc & 0xFF) ^ (crc >> 8)
    assert hashing.crc16(b"123456789") == 0x29B1


def test_spec_hash_covers_behaviour_but_not_docs() -> None:
    base = spec().spec_hash
    assert spec(GOOD.replace("Left wheel target speed", "Left wheel speed")).spec_hash == base
    assert (
        spec(
            GOOD.replace(
                'max = 1571, unit = "mrad", doc = "Front-wheel angle, positive',
                'max = 1500, unit = "mrad", doc = "Front-wheel angle, positive',
            )
        ).spec_hash
        != base
    )
    assert (
        spec(
            GOOD.replace(
                '{ from = ["IDLE"], event = "DISARM", to = "IDLE", actions = ["ack"] }',
                '{ from = ["IDLE"], event = "DISARM", to = "IDLE", actions = ["nack"] }',
            )
        ).spec_hash
        != base
    )


def test_generated_python_state_table_is_the_spec_table() -> None:
    from emulator.firmware.statemachine import INITIAL_STATE, TRANSITIONS

    s = spec()
    rows = [
        (
            t.source.name,
            t.event.name,
            t.guard.name.lower() if t.guard is not None else None,
            t.negated,
            t.target.name,
            tuple(a.name.lower() for a in type(t.actions) if a in t.actions),
        )
        for t in TRANSITIONS
    ]
    expected = [
        (src, ev, g, neg, to, tuple(sorted(acts, key=[a.name for a in s.state_machine.actions].index)))
        for src, ev, g, neg, to, acts in s.state_machine.rows()
    ]
    assert rows == expected
    assert INITIAL_STATE.name == s.state_machine.initial


def test_vectors_cover_every_message_and_the_required_cases() -> None:
    s = spec()
    for m in s.messages:
        data = json.loads((ROOT / "protocol" / "vectors" / f"{m.name.lower()}.json").read_text())
        cases = [v["case"] for v in data["vectors"]]
        assert {"zero", "min", "max", "typical"} <= set(cases), m.name
        lengths = {len(bytes.fromhex(v["payload"])) for v in data["vectors"]}
        if m.trailing is not None:
            assert {m.payload_size, m.payload_max} <= lengths, f"{m.name}: trailing array at 0 and max length"
        zero = next(v for v in data["vectors"] if v["case"] == "zero")
        if m.payload_size and all(f.lo <= 0 for f in m.fields if f.enum is None):
            assert bytes.fromhex(zero["payload"]).count(0) > 0, f"{m.name}: zero case exercises COBS"
    negatives = [
        v
        for m in s.messages
        for v in json.loads((ROOT / "protocol" / "vectors" / f"{m.name.lower()}.json").read_text())["vectors"]
        if v["case"] == "min"
        and any(isinstance(x, int) and x < 0 for x in json.dumps(v["fields"]) and v["fields"].values())
    ]
    assert negatives, "min vectors hold negative values"


def test_a_bound_may_name_a_constant_and_means_its_value() -> None:
    s = spec()
    consts = {c.name: c.value for c in s.constants}
    watchdog = next(f for f in s.message("SET_CONFIG").fields if f.name == "watchdog_ms")
    assert (watchdog.min, watchdog.max) == (consts["WATCHDOG_MIN_MS"], consts["WATCHDOG_MAX_MS"])
    as_numbers = f"min = {consts['WATCHDOG_MIN_MS']}, max = {consts['WATCHDOG_MAX_MS']}"
    assert spec(GOOD.replace('min = "WATCHDOG_MIN_MS", max = "WATCHDOG_MAX_MS"', as_numbers)).spec_hash == s.spec_hash


def test_every_explicit_integer_bound_has_a_name_on_both_sides() -> None:
    from protocol.generated.messages import BY_ID

    header = (ROOT / "arduino/RoverLink/src/generated/roverlink_protocol.h").read_text(encoding="utf-8")
    named = 0
    for m in spec().messages:
        cls = BY_ID[m.id]
        for f in m.fields:
            if f.is_float or f.enum is not None or f.max_len is not None:
                continue
            for suffix, bound in (("MIN", f.min), ("MAX", f.max)):
                name = f"{f.name.upper()}_{suffix}"
                if bound is None:
                    assert not hasattr(cls, name)
                    continue
                assert getattr(cls, name) == bound, (m.name, name)
                assert re.search(rf"\b{name} = {int(bound)}(UL)?\b", header), (m.name, name)
                named += 1
    assert named > 20  # SET_CONFIG alone has more


def test_link_stats_is_its_two_counter_sets_and_the_cpp_checks_where_they_sit() -> None:
    from protocol.generated.messages import LinkStats
    from protocol.generated.structs import DECODER_COUNTERS, LINK_COUNTERS, DecoderCounters, LinkCountersSnapshot

    assert [f.name for f in LinkStats.FIELDS] == ["req_seq", *DECODER_COUNTERS, *LINK_COUNTERS]
    assert tuple(DecoderCounters.__dataclass_fields__) == DECODER_COUNTERS
    assert tuple(LinkCountersSnapshot.__dataclass_fields__) == LINK_COUNTERS
    source = render(spec())["arduino/RoverLink/src/generated/roverlink_protocol.cpp"]
    for name in DECODER_COUNTERS[1:]:
        assert (
            f"offsetof(LinkStats, {name}) - offsetof(LinkStats, frames_ok) == offsetof(DecoderCounters, {name})"
            in source
        )
    for name in LINK_COUNTERS[1:]:
        assert (
            f"offsetof(LinkStats, {name}) - offsetof(LinkStats, seq_gaps) == offsetof(LinkCounters, {name})" in source
        )
    assert 'static_assert(sizeof(DecoderCounters) == 28, "DecoderCounters must have no padding");' in source


def test_the_hardware_contract_is_one_definition_for_the_hal_the_emulator_and_the_tests() -> None:
    from protocol.generated.hardware import Lights, MotorMode

    contract = hardware.load(generate.SPEC.parent / "hardware.toml", ROOT, spec())
    by_name = {e.name: {v.name: v.value for v in e.values} for e in contract.enums}
    assert by_name["MotorMode"] == {m.name: m.value for m in MotorMode}
    assert by_name["Lights"] == {str(m.name): m.value for m in Lights}
    header = (ROOT / "arduino/RoverLink/src/generated/roverlink_hardware.h").read_text(encoding="utf-8")
    for name, value in by_name["MotorMode"].items():
        assert f"    {name} = {value}," in header
    board = (ROOT / "arduino/RoverLink/src/hal/board.h").read_text(encoding="utf-8")
    assert '#include "../generated/roverlink_hardware.h"' in board and "enum class MotorMode" not in board


def test_a_hardware_enum_may_not_take_a_name_of_the_spec() -> None:
    text = (generate.SPEC.parent / "hardware.toml").read_text(encoding="utf-8")
    with pytest.raises(loader.SpecError, match=r"enums\[1\] Status: 'Status' is already a name in protocol/spec/"):
        hardware.parse(text.replace('name = "Lights"', 'name = "Status"'), "protocol/spec/hardware.toml", spec())
