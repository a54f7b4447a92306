"""The Arduino firmware, built with avr-gcc as a user builds it: budgets, build tool, hardware layer.

Every example is compiled once per session for its board with `roverlink.firmware` (the
`roverlink firmware build` tool: Arduino core, library src/ and sketch with -Werror on our code,
LTO, --gc-sections), and the figures are checked against the design brief's budgets (section 6):

* a complete reference firmware on the Uno leaves >= 50% of flash and SRAM free;
* link + session alone (the Session component of the core over a do-nothing App and Board, less a
  sketch that only uses Serial) costs <= 4 KB of flash and <= 400 B of SRAM.

`pytest -s` prints the figures; each test also records them as junit properties.

The AVR hardware layer on a simulated MCU is tested in test_avr_hal.py.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from protocol.generated.profiles import PROFILES
from roverlink import firmware
from tests.support.avr_build import (
    EXAMPLES,
    LIBRARY,
    ROOT,
    build_sketch,
    firmware_cli,
    report,
    require_toolchain,
    write_sketch,
)

UNO_FREE_FRACTION = 0.50
LINK_SESSION_FLASH_MAX = 4096
LINK_SESSION_SRAM_MAX = 400

# A sketch that only moves bytes through Serial: the baseline link + session is measured against,
# so the Arduino core and HardwareSerial (which any serial firmware has) are not counted.
SERIAL_ONLY_SKETCH = """\
void setup() { Serial.begin(115200); }

void loop() {
    if (Serial.available() > 0) {
        Serial.write(static_cast<uint8_t>(Serial.read()));
    }
}
"""

# The session alone (src/core/session.h: the link, the protocol and every session rule) over an App
# and a Board that do nothing, without the control law, the PID, the EEPROM image or any driver.
# Honest by construction: every answer the App gives comes from `unknown`, a volatile the compiler
# cannot see through, and everything the session hands the App goes to `sink`, so no message
# handler, reply, NACK reason or branch can be optimised away; the control tick's session duties
# (watchdog, FAULT, the FEEDBACK schedule) and a LOG are exercised as the firmware does.
LINK_SESSION_SKETCH = """\
#include <RoverLink.h>

using namespace roverlink;

volatile uint8_t unknown;  // never written: the compiler cannot know any answer below
volatile uint32_t sink;    // never read: everything the session hands over ends here

// Keeps time and gives "entropy"; the session needs nothing else from a Board.
class ClockBoard : public Board {
public:
    uint32_t micros() override { return ::micros(); }
    void read_encoders(int32_t counts[proto::WHEEL_COUNT]) override { counts[0] = counts[1] = 0; }
    void zero_encoders() override {}
    void drive(uint8_t, int16_t, MotorMode) override {}
    void esc_pulse(uint16_t) override {}
    void steering_pulse(uint16_t) override {}
    void lights(uint8_t) override {}
    bool eeprom_read(uint16_t, uint8_t*, uint16_t) override { return false; }
    bool eeprom_write(uint16_t, const uint8_t*, uint16_t) override { return false; }
    uint32_t entropy() override { return unknown; }
};

// The robot side of the session (session.h's App), doing nothing but keeping what it is sent.
class NullApp {
public:
    void session_actions(uint16_t actions) { sink = actions; }
    const proto::SetConfig& config() const { return cfg_; }
    uint8_t set_config(const proto::SetConfig& c, uint8_t& detail) {
        detail = unknown;
        if (detail == proto::ALL_FIELDS_VALID) {
            cfg_ = c;
        }
        return unknown;
    }
    void set_pid(const proto::SetPid& m) { pid_ = m; }
    void pid(uint8_t, proto::SetPid& out) { out = pid_; }
    uint8_t save_config() { return unknown; }
    void reset_odometry() { sink = 0; }
    void request(const proto::HostToMcu&, uint8_t id) { sink = id; }
    void setpoint(int16_t left, int16_t right, int16_t steer_mrad, uint8_t seq) {
        sink = static_cast<uint32_t>(left) ^ right ^ steer_mrad ^ seq;
    }
    uint8_t status_bits() const { return unknown; }

private:
    proto::SetConfig cfg_;
    proto::SetPid pid_;
};

ClockBoard board;
NullApp app;
// Every capability: every setpoint kind is handled, none refused as UNSUPPORTED at compile time.
static const Robot ROBOT = {"LinkSession", proto::Board::UNO, 0xFF, proto::FeedbackMode::STREAM, 0, 0,
                           proto::LightsMode::AUTO};
Session<NullApp> session(Serial, board, ROBOT, app);
const char TEXT[] ROVERLINK_PROGMEM = "link only: ";

void setup() {
    Serial.begin(115200);
    session.begin(unknown);
    const char tail[] = {static_cast<char>(unknown)};
    session.log(proto::LogLevel::INFO, TEXT, tail, unknown & 1);
}

void loop() {
    session.poll();
    static uint32_t last;
    const uint32_t now = session.clock();
    if (now - last >= 10000UL) {  // a control tick: the session's duties in it
        last = now;
        session.check_watchdog(now);
        if (unknown & 2) {
            session.fault(proto::FailsafeReason::ENCODER_FAULT);
        }
        if (session.feedback_due(unknown & 4)) {
            proto::Feedback f = proto::Feedback();
            f.mcu_time_us = now;
            session.send_feedback(f);
        }
    }
}
"""


# -- the examples ------------------------------------------------------------------------------------
def test_every_profile_has_an_example_sketch() -> None:
    assert sorted(firmware.examples()) == EXAMPLES


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_builds_for_its_board(
    example_builds: dict[str, firmware.BuildResult], name: str, record_property: pytest.RecordProperty
) -> None:
    result = example_builds[name]
    report(record_property, result)
    profile_board = next(p.board for p in PROFILES.values() if p.example == name)
    assert result.board.proto_board == profile_board
    assert result.elf.stat().st_size > 0
    lines = result.hex.read_text(encoding="ascii").splitlines()
    assert lines[0].startswith(":") and lines[-1] == ":00000001FF"  # Intel HEX, with its end record
    assert 0 < result.flash_used <= result.board.flash_bytes
    assert 0 < result.sram_used < result.board.sram_bytes


def test_robot_shows_flash_estimates_are_the_builds_figures(example_builds: dict[str, firmware.BuildResult]) -> None:
    """`roverlink robot show` estimates a file's flash from these builds: within 2 % of what they are."""
    from roverlink.commands.robot import REFERENCE_FLASH

    for example, size in set(REFERENCE_FLASH.values()):
        built = example_builds[example].flash_used
        assert abs(size - built) <= 0.02 * built, (example, size, built)


def test_uno_firmware_leaves_half_of_flash_and_sram_free(
    example_builds: dict[str, firmware.BuildResult], record_property: pytest.RecordProperty
) -> None:
    uno = [r for r in example_builds.values() if r.board.name == "uno"]
    assert uno, "no reference firmware targets the Uno"
    problems = []
    for result in uno:
        report(record_property, result)
        flash_max = int(result.board.flash_bytes * UNO_FREE_FRACTION)
        sram_max = int(result.board.sram_bytes * UNO_FREE_FRACTION)
        if result.flash_used > flash_max:
            problems.append(f"{result.name}: flash {result.flash_used} B > {flash_max} B (50% of the Uno)")
        if result.sram_used > sram_max:
            problems.append(f"{result.name}: SRAM {result.sram_used} B > {sram_max} B (50% of the Uno)")
    assert not problems, "; ".join(problems)


@pytest.fixture(scope="module")
def link_session_size(tmp_path_factory: pytest.TempPathFactory) -> tuple[int, int, Path]:
    """(flash, SRAM) of link + session alone on the Uno: the LinkSession sketch minus SerialOnly."""
    require_toolchain()
    tmp_path = tmp_path_factory.mktemp("link-session")
    baseline = build_sketch(write_sketch(tmp_path, "SerialOnly", SERIAL_ONLY_SKETCH), "uno", tmp_path / "out-serial")
    link = build_sketch(write_sketch(tmp_path, "LinkSession", LINK_SESSION_SKETCH), "uno", tmp_path / "out-link")
    print(f"\n    = {link.summary()}\n    - {baseline.summary()}")
    return link.flash_used - baseline.flash_used, link.sram_used - baseline.sram_used, tmp_path


def test_link_and_session_alone_fit_their_sram_budget(
    link_session_size: tuple[int, int, Path], record_property: pytest.RecordProperty
) -> None:
    _flash, sram, _ = link_session_size
    record_property("link_session.sram_bytes", sram)
    print(f"\n  link + session (uno): SRAM {sram:,} B (budget {LINK_SESSION_SRAM_MAX})")
    assert sram <= LINK_SESSION_SRAM_MAX, f"link + session use {sram} B of SRAM > {LINK_SESSION_SRAM_MAX} B"


def test_link_and_session_alone_fit_their_flash_budget(
    link_session_size: tuple[int, int, Path],
    record_property: pytest.RecordProperty,
    capsys: pytest.CaptureFixture[str],
) -> None:
    flash, sram, tmp_path = link_session_size
    record_property("link_session.flash_bytes", flash)
    with capsys.disabled():
        print(f"\n  link + session (uno): flash {flash:,} B (budget {LINK_SESSION_FLASH_MAX:,}), SRAM {sram:,} B")
        # The same difference split by where each byte's code comes from (the LTO builds measured).
        link = _flash_by_source(tmp_path / "out-link" / "LinkSession.elf")
        base = _flash_by_source(tmp_path / "out-serial" / "SerialOnly.elf")
        print("    of which, by source (LinkSession less SerialOnly):")
        for source in SOURCES:
            delta = link.get(source, 0) - base.get(source, 0)
            print(f"      {delta:6,} B  {source}")
    if flash > LINK_SESSION_FLASH_MAX:
        # Where the bytes go, from a build without LTO (LTO inlines most of the core into main()).
        plain = firmware.Builder(firmware.board_spec("uno"), lto=False).build(
            tmp_path / "LinkSession", tmp_path / "out-link-nolto"
        )
        with capsys.disabled():
            print("    flash by area, without LTO:")
            for area, size in sorted(_flash_by_area(plain.elf).items(), key=lambda kv: -kv[1]):
                print(f"      {size:6,} B  {area}")
    assert flash <= LINK_SESSION_FLASH_MAX, f"link + session use {flash} B of flash > {LINK_SESSION_FLASH_MAX} B"


LIBRARY_SOURCES = "library (arduino/RoverLink/src: codec, generated protocol, link, session)"
SKETCH_SOURCES = "the sketch (its do-nothing App and Board, setup() and loop())"
CORE_SOURCES = "Arduino core (micros(), Serial)"
OTHER_SOURCES = "libgcc and libc (prologues, multiply, memcpy), vectors, the C runtime"
SOURCES = (LIBRARY_SOURCES, SKETCH_SOURCES, CORE_SOURCES, OTHER_SOURCES)
_CODE_LINE = re.compile(r"^\s+[0-9a-f]+:\t((?:[0-9a-f]{2} )+)")
_SYMBOL = re.compile(r"^[0-9a-f]+ <(.*)>:$")


def _flash_by_source(elf: Path) -> dict[str, int]:
    """Flash bytes of an ELF by the source of each instruction (avr-objdump's line table); bytes
    without a line are the library's when their symbol is (its tables in flash), else libgcc/libc.
    .data's initial values, stored in flash too, count as the sketch's."""
    dump = subprocess.run(["avr-objdump", "-d", "-l", "-C", str(elf)], capture_output=True, text=True, check=True)
    out: dict[str, int] = {}
    symbol = ""
    source: str | None = None
    for line in dump.stdout.splitlines():
        m = _SYMBOL.match(line)
        if m:
            symbol, source = m.group(1), None
            continue
        if line.startswith("/") and re.match(r"^/\S+:\d+", line):
            path = line.split(":")[0]
            source = (
                LIBRARY_SOURCES
                if "/arduino/RoverLink/src/" in path
                else CORE_SOURCES
                if "/cores/arduino/" in path
                else SKETCH_SOURCES
                if path.endswith(".ino") or ".ino." in path
                else OTHER_SOURCES
            )
            continue
        code = _CODE_LINE.match(line)
        if code:
            where = source or (LIBRARY_SOURCES if symbol.startswith("roverlink::") else OTHER_SOURCES)
            out[where] = out.get(where, 0) + len(code.group(1).split())
    sizes = subprocess.run(["avr-size", "-A", str(elf)], capture_output=True, text=True, check=True).stdout
    data = next((int(row.split()[1]) for row in sizes.splitlines() if row.startswith(".data ")), 0)
    out[SKETCH_SOURCES] = out.get(SKETCH_SOURCES, 0) + data
    return out


AREAS = (
    ("roverlink::Session", "session (core/session.{h,cpp})"),
    ("roverlink::layout::", "layout helpers (wire/layout.cpp)"),
    ("roverlink::Firmware::", "control tick and the session's App (core/firmware.cpp)"),
    ("roverlink::control::", "control law (core/control.cpp)"),
    ("roverlink::config::", "configuration + EEPROM (core/config.cpp)"),
    ("roverlink::proto::", "generated protocol (checks, unpack, message and state tables)"),
    ("roverlink::", "codec + link"),
    ("__", "libgcc (float and long arithmetic)"),
)


def _flash_by_area(elf: Path) -> dict[str, int]:
    """Code and flash data of an ELF by source area, from its symbols."""
    text = subprocess.run(["avr-nm", "-C", "-S", str(elf)], capture_output=True, text=True, check=True).stdout
    areas: dict[str, int] = {}
    for line in text.splitlines():
        parts = line.split(maxsplit=3)
        if len(parts) < 4 or parts[2] not in "tTwWrR":
            continue
        area = next((label for prefix, label in AREAS if parts[3].startswith(prefix)), "Arduino core, libc, sketch")
        areas[area] = areas.get(area, 0) + int(parts[1], 16)
    return areas


# -- what the firmware sources must not contain -----------------------------------------------------------
FORBIDDEN = {
    "delay()": re.compile(r"\bdelay(Microseconds)?\s*\("),
    "String": re.compile(r"\bString\b"),
    "heap (malloc/new)": re.compile(r"\b(malloc|calloc|realloc|free|new)\b"),
    "Serial.print": re.compile(r"\bSerial\d?\s*\.\s*print"),
}


def _code_only(text: str) -> str:
    """C++ source with comments and string / char literals blanked out."""
    pattern = re.compile(r'//[^\n]*|/\*.*?\*/|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.DOTALL)
    return pattern.sub(lambda m: "\n" * m.group(0).count("\n") if m.group(0)[0] == "/" else '""', text)


def _checked_sources() -> list[Path]:
    sketches = sorted(LIBRARY.glob("examples/*/*.ino"))
    hal = sorted(p for p in (LIBRARY / "src" / "hal" / "avr").iterdir() if p.suffix in (".h", ".cpp"))
    return sketches + hal


@pytest.mark.parametrize("path", _checked_sources(), ids=lambda p: str(p.relative_to(LIBRARY)))
def test_no_delay_string_heap_or_text_output(path: Path) -> None:
    code = _code_only(path.read_text(encoding="utf-8"))
    found = [
        f"{what} on line {code[: m.start()].count(chr(10)) + 1}"
        for what, regex in FORBIDDEN.items()
        for m in regex.finditer(code)
    ]
    assert not found, f"{path.name}: {', '.join(found)}"


def test_the_forbidden_patterns_catch_what_they_should() -> None:
    code = _code_only('// delay(5) in a comment\nconst char* s = "Serial.print(x)";\nvoid f() { delay(5); }\n')
    assert FORBIDDEN["delay()"].search(code) and not FORBIDDEN["Serial.print"].search(code)
    assert code.count("\n") == 3
    assert FORBIDDEN["heap (malloc/new)"].search("int* p = new int;")
    assert FORBIDDEN["Serial.print"].search("Serial . println(1);")
    assert not FORBIDDEN["String"].search("StringView x;")


# -- the build tool ------------------------------------------------------------------------------------------
def test_rebuild_of_an_unchanged_sketch_reuses_everything(example_builds: dict[str, firmware.BuildResult]) -> None:
    first = example_builds["AckermannPiCar"]
    again = firmware.build_example("AckermannPiCar", out_dir=first.elf.parent)
    assert not again.linked
    assert (again.flash_used, again.sram_used) == (first.flash_used, first.sram_used)


def test_warnings_in_our_code_are_errors(tmp_path: Path) -> None:
    require_toolchain()
    sketch = write_sketch(tmp_path, "Warns", "void setup() { int unused = 1; }\nvoid loop() {}\n")
    with pytest.raises(firmware.CompileError, match="unused"):
        firmware.build_sketch(sketch, "uno", tmp_path / "out")


def test_sizes_agree_with_avr_size_c(example_builds: dict[str, firmware.BuildResult]) -> None:
    """Our flash / SRAM figures are the ones the Arduino IDE prints (avr-size -C)."""
    result = example_builds["AckermannPiCar"]
    text = subprocess.run(
        ["avr-size", "-C", f"--mcu={result.board.mcu}", str(result.elf)], capture_output=True, text=True, check=True
    ).stdout
    program = re.search(r"Program:\s+(\d+) bytes", text)
    data = re.search(r"Data:\s+(\d+) bytes", text)
    assert program and data, text
    assert (int(program.group(1)), int(data.group(1))) == (result.flash_used, result.sram_used)


def test_unknown_example_names_the_allowed_ones(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = firmware_cli(capsys, "firmware", "build", "--example", "NoSuchRobot")
    assert code == 2
    assert "'NoSuchRobot'" in err
    for name in EXAMPLES:
        assert name in err


def test_unknown_board_names_the_allowed_ones(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = firmware_cli(capsys, "firmware", "build", "--board", "due")
    assert code == 2
    assert "'due'" in err and "uno" in err and "mega2560" in err
    with pytest.raises(firmware.UnknownNameError, match=r"'leonardo'.*mega2560, uno"):
        firmware.board_spec("leonardo")


def test_sketch_needs_a_board(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = firmware_cli(capsys, "firmware", "build", "--sketch", str(tmp_path))
    assert code == 2 and "--board" in err and "uno" in err


@pytest.mark.parametrize(
    ("example", "expected"),
    [
        ("AckermannPiCar", "avrdude -p atmega328p -c arduino -P /dev/ttyACM0 -b 115200 -U flash:w:{hex}:i"),
        ("DiffDriveTB6612", "avrdude -p atmega2560 -c wiring -P /dev/ttyACM0 -b 115200 -D -U flash:w:{hex}:i"),
        ("DiffDriveBTS7960", "avrdude -p atmega2560 -c wiring -P /dev/ttyACM0 -b 115200 -D -U flash:w:{hex}:i"),
    ],
)
def test_flash_dry_run_prints_the_avrdude_command(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, example: str, expected: str
) -> None:
    code, out, _ = firmware_cli(
        capsys, "firmware", "flash", "--example", example, "--port", "/dev/ttyACM0", "--out", str(tmp_path), "--dry-run"
    )
    assert code == 0
    command = out.strip().splitlines()[-1]
    assert shlex.split(command) == shlex.split(expected.format(hex=tmp_path / f"{example}.hex"))
    assert not (tmp_path / f"{example}.hex").exists()  # a dry run builds and flashes nothing


def test_missing_toolchain_says_what_to_install(tmp_path: Path) -> None:
    env = {"PATH": str(tmp_path), "PYTHONPATH": str(ROOT)}
    result = subprocess.run(
        [sys.executable, "-m", "roverlink", "firmware", "build", "--example", "AckermannPiCar"],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        cwd=ROOT,
    )
    assert result.returncode == 2
    assert "avr-g++ not found" in result.stderr
    for package in ("gcc-avr", "avr-libc", "binutils-avr", "arduino-core-avr"):
        assert package in result.stderr


def test_missing_arduino_core_says_what_to_install(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv(firmware.CORE_DIR_ENV, str(tmp_path))
    with pytest.raises(firmware.ToolchainMissingError, match="arduino-core-avr"):
        firmware.arduino_core_dir()


def test_flash_without_avrdude_says_what_to_install(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv("PATH", "/nonexistent")
    code, _, err = firmware_cli(capsys, "firmware", "flash", "--example", "AckermannPiCar", "--port", "/dev/ttyACM0")
    assert code == 2 and "avrdude" in err and "apt-get install avrdude" in err
