"""The generator refuses a bad spec with an error naming the file, the entry and the problem."""

from __future__ import annotations

import pytest

from protocol.generator import loader
from protocol.generator.generate import SPEC

GOOD = SPEC.read_text(encoding="utf-8")
PATH = "protocol/spec/roverlink.toml"


def load_with(old: str, new: str, count: int = 1) -> loader.SpecError:
    assert GOOD.count(old) >= count, f"fixture text not found in the spec: {old!r}"
    text = GOOD.replace(old, new, count)
    with pytest.raises(loader.SpecError) as info:
        loader.parse(text, PATH)
    return info.value


def test_the_real_spec_is_valid() -> None:
    spec = loader.parse(GOOD, PATH)
    assert spec.version == 2  # 2: a lockstep session streams FEEDBACK while not armed
    assert spec.max_payload == 64
    assert {m.name for m in spec.messages} >= {
        "HELLO", "IDENTITY", "ARM", "DISARM", "PING", "PONG", "ACK", "NACK", "SET_WHEEL_SPEEDS",
        "SET_ACKERMANN", "FEEDBACK", "SET_PID", "GET_PID", "PID", "SET_CONFIG", "GET_CONFIG", "CONFIG",
        "SAVE_CONFIG", "RESET_ODOMETRY", "LINK_STATS", "LOG",
    }  # fmt: skip


@pytest.mark.parametrize(
    ("old", "new", "entry", "problem"),
    [
        pytest.param('id = 0x02\nname = "PING"', 'id = 0x01\nname = "PING"', "messages[1]", "duplicate message id 1", id="duplicate-id"),
        pytest.param('name = "PING"', 'name = "HELLO"', "messages[1]", "duplicate message name 'HELLO'", id="duplicate-name"),
        pytest.param('{ name = "wheel", type = "u8", doc = "Wheel index (0..WHEEL_COUNT-1) or', '{ name = "delete", type = "u8", doc = "x', "SET_PID > fields[0]", "'delete' is reserved (a C++ keyword)", id="cpp-keyword"),
        pytest.param('{ name = "wheel", type = "u8", doc = "Wheel index (0..WHEEL_COUNT-1)." }', '{ name = "lambda", type = "u8", doc = "x" }', "GET_PID > fields[0]", "'lambda' is reserved (a Python keyword)", id="python-keyword"),
        pytest.param('{ name = "wheel", type = "u8", doc = "Wheel index (0..WHEEL_COUNT-1)." }', '{ name = "min", type = "u8", doc = "x" }', "GET_PID > fields[0]", "'min' is reserved (an Arduino core", id="arduino-macro"),
        pytest.param('name = "UNKNOWN", value = 0', 'name = "HIGH", value = 0', "enums[0] Board > values[0]", "'HIGH' is reserved", id="arduino-macro-enum"),
        pytest.param('type = "char[..60]"', 'type = "char[..64]"', "messages[", "payload of up to 65 bytes exceeds max_payload 64", id="payload-too-big"),
        pytest.param('{ name = "host_time_us", type = "u32", unit = "us", doc = "Host clock', '{ name = "host_time_us", type = "u24", unit = "us", doc = "Host clock', "PING > fields[0] host_time_us", "unknown type 'u24'", id="unknown-type"),
        pytest.param('{ name = "MEGA2560", value = 4,', '{ name = "MEGA2560", value = 256,', "enums[0] Board > values[4] MEGA2560", "value 256 does not fit the base type u8", id="enum-value-too-big"),
        pytest.param('type = "u8[3]"', 'type = "u8[..3]"', "IDENTITY > fields[2] firmware_version", "variable-length array must be the last field", id="variable-not-last"),
        pytest.param('{ name = "FAILSAFE", doc = "Latched after', '{ name = "LIMBO", doc = "never entered" },\n  { name = "FAILSAFE", doc = "Latched after', "state_machine.states", "state LIMBO is unreachable from BOOT", id="unreachable-state"),
        pytest.param('{ name = "RESET", doc =', '{ name = "NEVER", doc = "no row" },\n  { name = "RESET", doc =', "state_machine.events", "event NEVER has no transition", id="event-without-transition"),
        pytest.param('id = 0x90\nname = "FEEDBACK"', 'id = 0x30\nname = "FEEDBACK"', "messages[", "mcu_to_host ids 0x80 and above", id="direction-id-range"),
        pytest.param('{ name = "SATURATED", value = 0x08,', '{ name = "SATURATED", value = 0x0C,', "enums[", "must be a single bit", id="flag-not-single-bit"),
        pytest.param('min = "WATCHDOG_MIN_MS", max = "WATCHDOG_MAX_MS", unit = "ms", doc = "Default watchdog', 'min = 2000, max = 50, unit = "ms", doc = "Default watchdog', "fields[0]", "min 2000 is greater than max 50", id="min-over-max"),
        pytest.param('min = "WATCHDOG_MIN_MS", max = "WATCHDOG_MAX_MS"', 'min = "WATCHDOG_MINIMUM", max = "WATCHDOG_MAX_MS"', "config > fields[0] watchdog_ms", "min 'WATCHDOG_MINIMUM' is not a constant", id="bound-names-no-constant"),
        pytest.param('struct = "LinkCounters"', 'struct = "LinkStats"', "top level", "field set struct 'LinkStats' collides with a message class", id="struct-name-collision"),
        pytest.param('struct = "LinkCounters"', 'struct = "link_counters"', "field_sets[3]", "must be CamelCase", id="struct-name-style"),
        pytest.param('{ name = "seq_gaps", type = "u32",', '{ name = "seq_gaps", type = "f32",', "link_counters > seq_gaps", "scalar integer fields only", id="struct-float-field"),
        pytest.param('id = 0x02\nname = "PING"\ndirection', 'id = 0x02\nname = "PING"\ndirektion = "x"\ndirection', "messages[1]", "unknown key(s): direktion", id="unknown-key"),
        pytest.param('event = "INIT_DONE", to = "IDLE"', 'event = "INIT_DONE", to = "LIMBO"', "state_machine.transitions[0]", "unknown state 'LIMBO'", id="unknown-target-state"),
        pytest.param('guard = "compatible", to = "DISARMED", actions = ["accept_hello"] }', 'guard = "compatible", to = "DISARMED", actions = ["accept_helo"] }', "state_machine.transitions[1]", "unknown action 'accept_helo'", id="unknown-action"),
        pytest.param('{ name = "SESSION", value = 0x01,', '{ name = "SESSION", value = 0x01, bits = 1,', "Status > values[0]", "unknown key(s): bits", id="unknown-enum-key"),
        pytest.param('guard = "compatible", to = "DISARMED"', 'guard = 7, to = "DISARMED"', "state_machine.transitions[1]", "'guard' must be str, got 7", id="guard-not-text"),
        pytest.param('event = "INIT_DONE", to = "IDLE"', 'event = ["INIT_DONE"], to = "IDLE"', "state_machine.transitions[0]", "'event' must be str", id="event-not-text"),
        pytest.param('event = "INIT_DONE", to = "IDLE"', 'event = "INIT_DONE", to = 1', "state_machine.transitions[0]", "'to' must be str, got 1", id="target-not-text"),
    ],
)  # fmt: skip
def test_invalid_spec_is_refused_with_file_entry_and_problem(old: str, new: str, entry: str, problem: str) -> None:
    err = load_with(old, new)
    text = str(err)
    assert text.startswith(PATH + ": "), text
    assert entry in err.entry, text
    assert problem in err.problem, text


def test_not_toml_is_refused() -> None:
    with pytest.raises(loader.SpecError, match="not valid TOML"):
        loader.parse("[protocol\nname=", PATH)


def test_a_row_after_an_unguarded_row_is_refused() -> None:
    err = load_with(
        '{ from = ["IDLE"], event = "ARM", to = "IDLE", actions = ["nack"] },',
        '{ from = ["IDLE"], event = "ARM", to = "IDLE", actions = ["nack"] },\n'
        '  { from = ["IDLE"], event = "ARM", to = "ARMED", actions = ["ack"] },',
    )
    assert "can never fire" in err.problem


def test_an_unused_guard_is_refused() -> None:
    err = load_with(
        '{ name = "boot_id_matches",', '{ name = "unused_guard", doc = "x" },\n  { name = "boot_id_matches",'
    )
    assert "guard unused_guard is never used" in err.problem


def test_cli_reports_spec_errors_without_a_traceback(
    tmp_path: pytest.TempPathFactory, capsys: pytest.CaptureFixture[str]
) -> None:
    from pathlib import Path

    from protocol.__main__ import main

    root = Path(str(tmp_path))
    bad = root / "protocol" / "spec" / "roverlink.toml"
    bad.parent.mkdir(parents=True)
    bad.write_text(
        GOOD.replace('type = "u32", unit = "us", doc = "Host clock', 'type = "u24", unit = "us", doc = "Host clock')
    )
    assert main(["check", "--spec", str(bad), "--root", str(root)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        "error: protocol/spec/roverlink.toml: messages[1] PING > fields[0] host_time_us: unknown type 'u24'"
    )
