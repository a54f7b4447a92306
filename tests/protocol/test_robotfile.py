"""Robot files (protocol.robotfile): the reference files round trip, and every check names the
file, the key, its line, the value and what is allowed."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from protocol.generated.profiles import PROFILES, ROBOT_SENSORS
from protocol.robotfile import REFERENCES, RobotFileError, check, load, parse, reference_path


def _variant(tmp_path: Path, name: str, old: str, new: str) -> Path:
    text = reference_path(name).read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "robot.toml"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    return path


def _problems(path: Path) -> list[str]:
    return [str(p) for p in check(path)]


@pytest.mark.parametrize("name", REFERENCES)
def test_reference_file_gives_the_reference_profile(name: str) -> None:
    robot, profile = load(reference_path(name)), PROFILES[name]
    assert robot.config() == profile.config
    assert robot.pid_gains() == profile.pid
    assert robot.wiring == profile.wiring
    assert robot.capabilities() == profile.capabilities
    assert robot.board_enum() == profile.board
    assert robot.feedback_mode() == profile.feedback_mode
    assert robot.lights_mode() == profile.lights_mode
    assert (robot.track_m, robot.geometry.wheelbase_m) == (profile.track_m, profile.wheelbase_m)
    assert robot.sensors() == ROBOT_SENSORS[name]
    assert robot.example == profile.example
    assert robot.path == str(reference_path(name))


def test_unknown_key_names_the_nearest_and_its_line(tmp_path: Path) -> None:
    path = _variant(tmp_path, "picar", "track_m = 0.16", "trak_m = 0.16")
    line = (
        path.read_text(encoding="utf-8")
        .splitlines()
        .index("trak_m = 0.16  # [m] Distance between the left and right wheels.")
        + 1
    )
    problems = _problems(path)
    assert f"{path}:{line}: geometry.trak_m: unknown key (did you mean 'track_m'?)" in problems
    assert any("missing key 'geometry.track_m'" in p for p in problems)


def test_wrong_type_and_out_of_range(tmp_path: Path) -> None:
    path = _variant(tmp_path, "picar", "watchdog_s = 0.25", 'watchdog_s = "fast"')
    assert any("limits.watchdog_s: = 'fast': expected a number (0.05..2 s)" in p for p in _problems(path))
    path = _variant(tmp_path, "picar", "watchdog_s = 0.25", "watchdog_s = 5.0")
    assert any("limits.watchdog_s: = 5.0: out of range (allowed: 0.05..2 s)" in p for p in _problems(path))


def test_servo_off_timer1_on_the_uno_names_the_constraint(tmp_path: Path) -> None:
    path = _variant(tmp_path, "picar", "pin = 10", "pin = 6")
    (problem,) = _problems(path)
    assert "esc 9, servo 6: the ESC and servo pulses need the pins of one 16-bit timer (Timer1: pins 9, 10)" in problem
    assert problem.startswith(f"{path}:")


def test_pin_used_twice(tmp_path: Path) -> None:
    path = _variant(tmp_path, "diffdrive-tb6612", "in2 = 25", "in2 = 22")
    assert any(
        "drive.motors[1].in2: = 22: pin already serves drive.motors[0].in1 (one function per pin)" in p
        for p in _problems(path)
    )


def test_encoder_pin_without_interrupt(tmp_path: Path) -> None:
    path = _variant(tmp_path, "diffdrive-tb6612", "a = 18", "a = 40")
    (problem,) = _problems(path)
    assert "encoders.pins[1].a: pin 40 cannot interrupt on the MEGA2560" in problem


def test_motor_pwm_pin_without_pwm(tmp_path: Path) -> None:
    path = _variant(tmp_path, "diffdrive-tb6612", "pwm = 7", "pwm = 40")
    assert any("drive.motors[1].pwm: pin 40 has no PWM output on the MEGA2560" in p for p in _problems(path))


def test_unknown_board_suggests(tmp_path: Path) -> None:
    path = _variant(tmp_path, "picar", 'board = "uno"', 'board = "unoo"')
    assert f"{path}:7: board: = 'unoo': not one of uno, mega2560, pico, native (did you mean 'uno'?)" in _problems(path)


def test_board_lacking_a_pin_the_file_asks_for(tmp_path: Path) -> None:
    path = _variant(tmp_path, "diffdrive-tb6612", 'board = "mega2560"', 'board = "uno"')
    problems = _problems(path)
    assert any("drive.motors[0].in1: = 22: 22 is not a pin of the UNO (0..19 or A0..A5)" in p for p in problems)
    assert len(problems) > 5  # every problem, not the first


def test_missing_file_and_not_toml(tmp_path: Path) -> None:
    assert _problems(tmp_path / "none.toml") == [f"{tmp_path / 'none.toml'}: no such file"]
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\nboard = \n', encoding="utf-8")
    (problem,) = _problems(bad)
    assert problem.startswith(f"{bad}:2: not valid TOML")


def test_load_raises_one_error_listing_all(tmp_path: Path) -> None:
    path = _variant(tmp_path, "picar", "watchdog_s = 0.25", "watchdog_s = 9.0\nspeed = 1")
    with pytest.raises(RobotFileError) as err:
        load(path)
    assert isinstance(err.value, ValueError)
    assert len(err.value.problems) == 2
    assert str(err.value).startswith(f"{path}: 2 problems\n")


def test_calibration_overrides_nominal_values(tmp_path: Path) -> None:
    path = _variant(tmp_path, "picar", "# wheel_diameter_m = ...", "wheel_diameter_m = 0.0662\nsteering_trim_deg = 1.5")
    config = load(path).config()
    assert (config.wheel_diameter_um, config.steering_center_cdeg) == (66200, 9150)
    # The servo's travel moves with its centre, as `roverlink calibrate` moves it on the board.
    assert (config.steering_min_cdeg, config.steering_max_cdeg) == (6650, 12650)


def test_docs_describe_every_key() -> None:
    from protocol.robotfile.schema import SECTIONS

    doc = (Path(__file__).resolve().parents[2] / "docs" / "robot-file.md").read_text(encoding="utf-8")
    for section, keys in SECTIONS.items():
        heading = f"### [{section}]" if section else "### Top level"
        assert heading in doc
        body = doc.split(heading, 1)[1].split("\n### ", 1)[0]
        for k in keys:
            row = [line for line in body.splitlines() if line.startswith(f"| `{k.name}` | {k.type} |")]
            assert row, (section, k.name)
            assert k.doc in row[0], (section, k.name, "the schema's meaning")


def test_docs_pwm_tables_are_the_hardware_facts() -> None:
    """robot-file.md's driver and timer tables say what hardware.toml says (a pin moved to another
    timer, or a driver's range changed, in one place only fails here)."""
    from protocol.generator.hardware import pwm_facts

    doc = (Path(__file__).resolve().parents[2] / "docs" / "robot-file.md").read_text(encoding="utf-8")
    section = doc.split("### Motor PWM pins", 1)[1].split("\n### ", 1)[0]
    rows = [[c.strip() for c in line.strip("|").split("|")] for line in section.splitlines() if line.startswith("| ")]
    facts = pwm_facts()

    def khz(hz: int) -> str:
        return f"{hz} Hz" if hz < 1000 else f"{hz / 1000:.1f} kHz"

    timed = ("Timer", "slice")
    timers = [(r[0].strip("`"), r[1], r[2]) for r in rows if r[1].startswith(timed)]
    assert timers == [(t.board.lower(), t.timer, ", ".join(map(str, t.pins))) for t in facts.timers]
    gives = {(r[0].strip("`"), r[1]): r[3] for r in rows if r[1].startswith(timed)}
    for t in facts.timers:
        assert gives[(t.board.lower(), t.timer)].startswith(", ".join(map(khz, t.hz))), t

    def span(lo: int, hi: int) -> str:
        if lo >= 1000:
            return f"{lo // 1000}..{hi // 1000} kHz"
        return f"{lo}..{hi} Hz" if hi <= 1000 else f"{lo} Hz..{hi // 1000} kHz"

    drivers = {r[0]: r[1] for r in rows if facts.driver(r[0]) is not None}
    assert set(drivers) == {d.driver for d in facts.drivers}
    for d in facts.drivers:
        assert drivers[d.driver].startswith(span(d.min_hz, d.max_hz) + ":"), (d, drivers[d.driver])


NUMBER_LINE = re.compile(r"^(?P<key>\w+) = (?P<value>-?\d[\d.eE+-]*)(?P<rest>\s*(#.*)?)$", re.MULTILINE)


@pytest.mark.parametrize("name", REFERENCES)
@pytest.mark.parametrize("bad", ["nan", "inf", "-inf"])
def test_every_number_must_be_finite_naming_its_key(name: str, bad: str) -> None:
    """TOML has nan and inf; every comparison with NaN is false, so a range check alone lets it in."""
    text = reference_path(name).read_text(encoding="utf-8")
    lines = list(NUMBER_LINE.finditer(text))
    assert len(lines) > 20, "the reference file's numbers were not found"
    for m in lines:
        edited = text[: m.start("value")] + bad + text[m.end("value") :]
        robot, problems = parse(edited, "robot.toml")
        named = [str(p) for p in problems if f".{m['key']}: = {bad}" in str(p) or f" {m['key']}: = {bad}" in str(p)]
        assert robot is None and named, f"{m['key']} = {bad} was not refused: {[str(p) for p in problems]}"
        assert "finite" in named[0] or "expected" in named[0], named  # what is allowed, said


def test_a_footprint_point_must_be_finite() -> None:
    text = reference_path("picar").read_text(encoding="utf-8")
    disc = "radius_m = 0.19"
    assert disc in text, "the PiCar's footprint was not found"
    edited = text.replace(disc, "polygon_m = [[0.3, 0.1], [nan, 0.1], [0.0, -0.1]]", 1)
    robot, problems = parse(edited, "robot.toml")
    assert robot is None and any("polygon_m" in str(p) and "finite" in str(p) for p in problems), problems


def test_lights_mode_names_what_is_allowed(tmp_path: Path) -> None:
    path = _variant(tmp_path, "diffdrive-tb6612", '\nmode = "auto"', '\nmode = "blink"')
    [problem] = _problems(path)
    assert "lights.mode" in problem and "'blink'" in problem and "one of auto, off" in problem
    assert load(_variant(tmp_path, "diffdrive-tb6612", '\nmode = "auto"', '\nmode = "off"')).lights_mode().name == "OFF"


def test_a_reference_robot_moves_to_the_pico_pinout_and_passes_its_rules() -> None:
    from protocol.robotfile import parse, reference_path
    from protocol.robotfile.pico import on_pico

    for name in ("diffdrive-tb6612", "diffdrive-bts7960", "picar"):
        text = on_pico(reference_path(name).read_text(encoding="utf-8"))
        robot, problems = parse(text, f"{name}-pico.toml")
        assert problems == [] and robot is not None, name
        assert robot.board == "pico" and robot.geometry == parse(reference_path(name).read_text(), name)[0].geometry  # type: ignore[union-attr]
        assert "Raspberry Pi Pico" in robot.description and "Mega" not in robot.description, robot.description
        assert "Uno" not in robot.description, robot.description


def test_pico_pin_rules_name_the_slice_and_the_header() -> None:
    from protocol.robotfile import parse, reference_path
    from protocol.robotfile.pico import on_pico

    car = on_pico(reference_path("picar").read_text(encoding="utf-8"))
    _, problems = parse(car.replace("pin = 3", "pin = 23"), "car.toml")
    assert any("pin 23 is not on the PICO's header (its pins: 0..22, 26..28)" in p.message for p in problems), problems
    tb = on_pico(reference_path("diffdrive-tb6612").read_text(encoding="utf-8"))
    _, problems = parse(tb.replace("a = 10,", "a = 25,"), "tb.toml")  # the LED's, not the header's
    assert any("pin 25 is not on the PICO's header" in p.message for p in problems), problems
    _, problems = parse(tb.replace("pwm = 2,", "pwm = 1,"), "tb.toml")
    assert any("serial port" in p.message for p in problems), problems
    _, problems = parse(tb.replace("pwm = 2,", "pwm = 29,"), "tb.toml")
    assert any("29 is not a pin of the PICO (0..28 or A0..A2)" in p.message for p in problems), problems
