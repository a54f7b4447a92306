"""The Arduino firmware, built with avr-gcc as a user builds it: budgets, build tool, hardware layer.

Every example is compiled once per session for its board with `roverlink.firmware` (the
`roverlink firmware build` tool: Arduino core, library src/ and sketch with -Werror on our code,
LTO, --gc-sections), and the figures are checked against the design brief's budgets (section 6):

* a complete reference firmware on the Uno leaves >= 50% of flash and SRAM free;
* link + session alone (the Session component of the core over a do-nothing App and Board, less a
  sketch that only uses Serial) costs <= 4 KB of flash and <= 400 B of SRAM.

`pytest -s` prints the figures; each test also records them as junit properties.

Then the AVR hardware layer runs in simavr (tests/firmware/native/avr_hal/sim_pins.c): test sketches for
Timer1 servo pulses, TB6612 / BTS7960 pins, LEDs and encoders on external and pin-change
interrupts, and every example booting and streaming frames with its outputs in the safe state.
"""

from __future__ import annotations

import dataclasses
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from host_sdk import messages
from host_sdk.framing import Frame, FrameDecoder
from protocol.generated.profiles import PROFILES
from roverlink import firmware
from roverlink.cli import main as cli_main

ROOT = Path(__file__).resolve().parents[2]
LIBRARY = ROOT / "arduino" / "RoverLink"
EXAMPLES = sorted(profile.example for profile in PROFILES.values())

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
static const Robot ROBOT = {"LinkSession", proto::Board::UNO, 0xFF, proto::FeedbackMode::STREAM, 0, 0};
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


def _require_toolchain() -> None:
    try:
        firmware.Toolchain.find()
    except firmware.ToolchainMissingError as exc:
        pytest.fail(f"{exc} (scripts/test.sh installs them)", pytrace=False)


def _build(sketch: Path, board: str, out: Path) -> firmware.BuildResult:
    try:
        return firmware.build_sketch(sketch, board, out)
    except firmware.CompileError as exc:
        error = exc
    pytest.fail(f"{sketch.name} does not build for {board}:\n{error}", pytrace=False)


def _write_sketch(root: Path, name: str, text: str) -> Path:
    sketch = root / name
    sketch.mkdir(parents=True, exist_ok=True)
    (sketch / f"{name}.ino").write_text(text, encoding="utf-8")
    return sketch


def _report(record_property: pytest.RecordProperty, result: firmware.BuildResult) -> None:
    print(f"\n  {result.summary()}")
    record_property(f"{result.name}.{result.board.name}.flash_bytes", result.flash_used)
    record_property(f"{result.name}.{result.board.name}.sram_bytes", result.sram_used)


@pytest.fixture(scope="session")
def example_builds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, firmware.BuildResult]:
    """Every example for its own board, built once per session (objects come from the build cache)."""
    _require_toolchain()
    out = tmp_path_factory.mktemp("firmware")
    results: dict[str, firmware.BuildResult] = {}
    failures: list[str] = []
    for name in EXAMPLES:
        try:
            results[name] = firmware.build_example(name, out_dir=out / name)
        except firmware.CompileError as exc:
            failures.append(f"{name}: {exc}")
    if failures:
        pytest.fail("examples that do not build:\n" + "\n\n".join(failures), pytrace=False)
    return results


# -- the examples ------------------------------------------------------------------------------------
def test_every_profile_has_an_example_sketch() -> None:
    assert sorted(firmware.examples()) == EXAMPLES


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_builds_for_its_board(
    example_builds: dict[str, firmware.BuildResult], name: str, record_property: pytest.RecordProperty
) -> None:
    result = example_builds[name]
    _report(record_property, result)
    profile_board = next(p.board for p in PROFILES.values() if p.example == name)
    assert result.board.proto_board == profile_board
    assert result.elf.stat().st_size > 0
    lines = result.hex.read_text(encoding="ascii").splitlines()
    assert lines[0].startswith(":") and lines[-1] == ":00000001FF"  # Intel HEX, with its end record
    assert 0 < result.flash_used <= result.board.flash_bytes
    assert 0 < result.sram_used < result.board.sram_bytes


def test_uno_firmware_leaves_half_of_flash_and_sram_free(
    example_builds: dict[str, firmware.BuildResult], record_property: pytest.RecordProperty
) -> None:
    uno = [r for r in example_builds.values() if r.board.name == "uno"]
    assert uno, "no reference firmware targets the Uno"
    problems = []
    for result in uno:
        _report(record_property, result)
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
    _require_toolchain()
    tmp_path = tmp_path_factory.mktemp("link-session")
    baseline = _build(_write_sketch(tmp_path, "SerialOnly", SERIAL_ONLY_SKETCH), "uno", tmp_path / "out-serial")
    link = _build(_write_sketch(tmp_path, "LinkSession", LINK_SESSION_SKETCH), "uno", tmp_path / "out-link")
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
    _require_toolchain()
    sketch = _write_sketch(tmp_path, "Warns", "void setup() { int unused = 1; }\nvoid loop() {}\n")
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


def _cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    try:
        code = cli_main(list(argv))
    except SystemExit as exc:  # argparse's own errors
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err


def test_unknown_example_names_the_allowed_ones(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _cli(capsys, "firmware", "build", "--example", "NoSuchRobot")
    assert code == 2
    assert "'NoSuchRobot'" in err
    for name in EXAMPLES:
        assert name in err


def test_unknown_board_names_the_allowed_ones(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = _cli(capsys, "firmware", "build", "--board", "due")
    assert code == 2
    assert "'due'" in err and "uno" in err and "mega2560" in err
    with pytest.raises(firmware.UnknownNameError, match=r"'leonardo'.*mega2560, uno"):
        firmware.board_spec("leonardo")


def test_sketch_needs_a_board(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, _, err = _cli(capsys, "firmware", "build", "--sketch", str(tmp_path))
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
    code, out, _ = _cli(
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
    code, _, err = _cli(capsys, "firmware", "flash", "--example", "AckermannPiCar", "--port", "/dev/ttyACM0")
    assert code == 2 and "avrdude" in err and "apt-get install avrdude" in err


# -- the hardware layer on a simulated MCU ----------------------------------------------------------------
# Test sketches run in simavr (tests/firmware/native/avr_hal/sim_pins.c): the harness drives encoder pins
# on a schedule and logs output pins and UART0. Digital pin levels and the register file are
# exact in simavr; the waveform of a 16-bit timer's compare output is not, so PWM and servo pulses
# are checked through the registers that make them (the sketches report them over the UART).

AVR_HAL_DIR = ROOT / "tests" / "firmware" / "native" / "avr_hal"
SIM_BUILD = ROOT / "build" / "native" / "avr_hal"
CYCLES_PER_US = 16
GRAY = ("00", "10", "11", "01")  # channel levels (A, B) at the four positions of a cycle


@dataclasses.dataclass
class SimRun:
    pins: dict[str, list[tuple[int, int]]]  # port pin -> (cycle, level) changes
    uart: bytes

    def level(self, pin: str, at_us: int) -> int:
        """Level of a watched output pin at a time (0 before its first change)."""
        level = 0
        for cycle, value in self.pins.get(pin, []):
            if cycle > at_us * CYCLES_PER_US:
                break
            level = value
        return level

    def records(self, size: int) -> list[bytes]:
        """The sketch's reports: 0xA5 then `size` bytes, back to back."""
        out, data = [], self.uart
        while len(data) >= size + 1:
            assert data[0] == 0xA5, data.hex()
            out.append(data[1 : size + 1])
            data = data[size + 1 :]
        return out


@pytest.fixture(scope="session")
def sim_pins() -> Path:
    if shutil.which("cc") is None or not Path("/usr/include/simavr/sim_avr.h").is_file():
        pytest.fail("simavr's library is required: install the Debian packages simavr libsimavr-dev libelf-dev")
    result = subprocess.run(
        ["make", "-C", str(AVR_HAL_DIR), "sim", f"BUILD={SIM_BUILD}"], capture_output=True, text=True, check=False
    )
    if result.returncode != 0:
        pytest.fail(f"building sim_pins failed:\n{result.stdout}\n{result.stderr}", pytrace=False)
    return SIM_BUILD / "sim" / "sim_pins"


def simulate(
    sim: Path, result: firmware.BuildResult, duration_us: int, watch: list[str], schedule: list[str]
) -> SimRun:
    run = subprocess.run(
        [str(sim), result.board.mcu, str(result.elf), str(duration_us), *watch],
        input="\n".join(schedule) + "\n",
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    pins: dict[str, list[tuple[int, int]]] = {}
    uart = b""
    for line in run.stdout.splitlines():
        words = line.split()
        if words[:1] == ["PIN"]:
            pins.setdefault(words[2], []).append((int(words[1]), int(words[3])))
        elif words[:1] == ["UART"]:
            uart = bytes.fromhex(words[1]) if len(words) > 1 else b""
    return SimRun(pins, uart)


def quadrature(pin_a: str, pin_b: str, start_us: int, moves: list[int], step_us: int = 50) -> list[str]:
    """Schedule lines turning an encoder that rests at 11 (the pull-ups) by `moves` (+1/-1/+2)."""
    lines, position, t = [], GRAY.index("11"), start_us
    for move in moves:
        position = (position + move) % 4
        t += step_us
        a, b = GRAY[position]
        lines += [f"{t} {pin_a} {a}", f"{t} {pin_b} {b}"]
    return lines


def _by_time(*schedules: list[str]) -> list[str]:
    return sorted((line for s in schedules for line in s), key=lambda line: int(line.split()[0]))


REPORT_EVERY_10_MS = """
void report(const uint8_t* data, uint8_t size) {
    Serial.write(0xA5);
    Serial.write(data, size);
}
"""

UNO_HAL_SKETCH = (
    """\
#include <RoverLink.h>
namespace rl = roverlink::avr;

rl::QuadratureEncoder encoder(2, 3);
rl::AckermannBoard<rl::Timer1> board(encoder, rl::PulseChannel::A, rl::PulseChannel::B, A0);
void edge() { encoder.on_edge(); }
"""
    + REPORT_EVERY_10_MS
    + """
void setup() {
    Serial.begin(115200);
    board.begin();
    encoder.attach_external(edge);
    board.esc_pulse(1500);
    board.steering_pulse(1222);
}

void loop() {
    static uint32_t last;
    static bool changed;
    const uint32_t now = micros();
    if (!changed && now >= 40000UL) {
        changed = true;
        board.esc_pulse(3000);    // clamped to 2600 us
        board.steering_pulse(0);  // pulses off, line held low
    }
    if (now - last >= 10000UL) {
        last = now;
        int32_t counts[2];
        board.read_encoders(counts);
        const uint16_t errors = encoder.errors(), ocr_a = OCR1A, ocr_b = OCR1B, top = ICR1;
        uint8_t r[18];
        memcpy(r, counts, 8);
        memcpy(r + 8, &errors, 2);
        r[10] = TCCR1A;
        r[11] = TCCR1B;
        memcpy(r + 12, &ocr_a, 2);
        memcpy(r + 14, &top, 2);
        memcpy(r + 16, &ocr_b, 2);
        report(r, 18);
    }
}
"""
)


def test_uno_servo_pulses_and_encoder_on_a_simulated_atmega328p(sim_pins: Path, tmp_path: Path) -> None:
    build = _build(_write_sketch(tmp_path, "UnoHal", UNO_HAL_SKETCH), "uno", tmp_path / "out")
    moves = [1] * 400 + [-1] * 100 + [2]  # 100 cycles forward, 25 back, then a missed edge
    run = simulate(sim_pins, build, 80_000, ["B1", "B2"], quadrature("D2", "D3", 5_000, moves))
    reports = run.records(18)
    assert len(reports) >= 6, run.uart.hex()
    first, last = reports[1], reports[-1]  # reports[0] may precede the pulses' setup
    # Timer1: fast PWM mode 14 (WGM13:10 = 1110), clk/8, TOP 39999: 20 ms period, 0.5 us ticks.
    assert first[11] == 0b00011010
    assert int.from_bytes(first[14:16], "little") == 39999
    assert first[10] == 0b10100010  # COM1A1 | COM1B1 (non-inverting) | WGM11
    assert int.from_bytes(first[12:14], "little") == 2 * 1500 - 1  # ESC: 1500 us
    assert int.from_bytes(first[16:18], "little") == 2 * 1222 - 1  # steering: 1222 us
    assert last[10] == 0b10000010  # steering channel disconnected...
    assert run.level("B2", 79_000) == 0  # ...and its line held low
    assert int.from_bytes(last[12:14], "little") == 2 * 2600 - 1  # 3000 us clamped
    # Encoder: x4 counts on INT0/INT1; the two-step jump counts nothing and is an error.
    assert int.from_bytes(last[0:4], "little", signed=True) == 4 * 75
    assert int.from_bytes(last[4:8], "little", signed=True) == 0  # no second wheel
    assert int.from_bytes(last[8:10], "little") == 1


MEGA_TB6612_SKETCH = (
    """\
#include <RoverLink.h>
namespace rl = roverlink::avr;
using roverlink::MotorMode;

rl::Tb6612Motor left_motor(6, 22, 23, 26), right_motor(7, 24, 25, 26);
rl::QuadratureEncoder left_encoder(2, 3), right_encoder(18, 19);
rl::TurnSignalLeds leds(30, 31, 32, 33);
rl::DiffDriveBoard<rl::Tb6612Motor, rl::TurnSignalLeds> board(left_motor, right_motor, left_encoder,
                                                              right_encoder, leds, A0);
void left_edge() { left_encoder.on_edge(); }
void right_edge() { right_encoder.on_edge(); }
"""
    + REPORT_EVERY_10_MS
    + """
void setup() {
    Serial.begin(115200);
    board.begin();
    rl::pwm_ultrasonic(6);
    left_encoder.attach_external(left_edge);
    right_encoder.attach_external(right_edge);
}

void loop() {
    static uint32_t last;
    const uint32_t now = micros();
    if (now < 30000UL) {
        board.drive(0, 500, MotorMode::DRIVE);
        board.drive(1, -1000, MotorMode::DRIVE);
        board.lights(roverlink::Lights::FRONT_LEFT | roverlink::Lights::REAR_LEFT);
    } else if (now < 60000UL) {
        board.drive(0, 0, MotorMode::BRAKE);
        board.drive(1, 0, MotorMode::BRAKE);
        board.lights(roverlink::Lights::FRONT_RIGHT | roverlink::Lights::REAR_RIGHT);
    } else {
        board.drive(0, 0, MotorMode::COAST);
        board.drive(1, 0, MotorMode::COAST);
        board.lights(0);
    }
    if (now - last >= 10000UL) {
        last = now;
        int32_t counts[2];
        board.read_encoders(counts);
        uint8_t r[11];
        memcpy(r, counts, 8);
        r[8] = TCCR4A;
        r[9] = TCCR4B;
        r[10] = OCR4AL;
        report(r, 11);
    }
}
"""
)

# Mega pins as port bits: 22..26 = PA0..PA4, 6/7 = PH3/PH4, 30..33 = PC7..PC4, 2/3 = PE4/PE5,
# 18/19 = PD3/PD2, 50..53 = PB3..PB0.
TB6612_PINS = {"AIN1": "A0", "AIN2": "A1", "BIN1": "A2", "BIN2": "A3", "STBY": "A4", "PWMA": "H3", "PWMB": "H4"}
LED_PINS = {"FL": "C7", "FR": "C6", "RL": "C5", "RR": "C4"}


def test_mega_tb6612_leds_and_external_interrupt_encoders(sim_pins: Path, tmp_path: Path) -> None:
    build = _build(_write_sketch(tmp_path, "Tb6612Hal", MEGA_TB6612_SKETCH), "mega2560", tmp_path / "out")
    schedule = _by_time(quadrature("E4", "E5", 5_000, [1] * 200), quadrature("D3", "D2", 5_025, [-1] * 120, step_us=70))
    watch = [*TB6612_PINS.values(), *LED_PINS.values()]
    run = simulate(sim_pins, build, 90_000, watch, schedule)

    def levels(at_us: int, names: dict[str, str]) -> dict[str, int]:
        return {name: run.level(pin, at_us) for name, pin in names.items()}

    pins = {k: v for k, v in TB6612_PINS.items() if k != "PWMA"}  # PWMA is on the timer: see registers
    assert levels(25_000, pins) == {"AIN1": 1, "AIN2": 0, "BIN1": 0, "BIN2": 1, "STBY": 1, "PWMB": 1}
    assert levels(25_000, LED_PINS) == {"FL": 1, "FR": 0, "RL": 1, "RR": 0}
    assert levels(55_000, TB6612_PINS) == {k: 1 for k in TB6612_PINS}  # short brake: all high
    assert levels(55_000, LED_PINS) == {"FL": 0, "FR": 1, "RL": 0, "RR": 1}
    coast = dict.fromkeys(TB6612_PINS, 0) | {"STBY": 1}
    assert levels(85_000, TB6612_PINS) == coast
    assert levels(85_000, LED_PINS) == dict.fromkeys(LED_PINS, 0)

    reports = run.records(11)
    assert len(reports) >= 8, run.uart.hex()
    driving = reports[1]  # at ~10 ms
    assert driving[8] & 0b10000000  # COM4A1: pin 6 on the timer
    assert driving[10] == 128  # 500 permille of 255, rounded
    assert driving[9] & 0b111 == 0b001  # pwm_ultrasonic(): Timer4 at clk/1
    assert reports[-1][8] & 0b10000000 == 0  # coasting: pin 6 off the timer, low
    counts = (
        int.from_bytes(reports[-1][0:4], "little", signed=True),
        int.from_bytes(reports[-1][4:8], "little", signed=True),
    )
    assert counts == (200, -120)


MEGA_BTS7960_SKETCH = (
    """\
#include <RoverLink.h>
namespace rl = roverlink::avr;
using roverlink::MotorMode;

rl::Bts7960Motor left_motor(2, 3, 22, 23), right_motor(6, 7, 24, 25);
rl::QuadratureEncoder left_encoder(50, 51), right_encoder(52, 53);
rl::NoLights no_lights;
rl::DiffDriveBoard<rl::Bts7960Motor> board(left_motor, right_motor, left_encoder, right_encoder, no_lights, A0);
ISR(PCINT0_vect) {
    left_encoder.on_edge();
    right_encoder.on_edge();
}
"""
    + REPORT_EVERY_10_MS
    + """
void setup() {
    Serial.begin(115200);
    board.begin();
    left_encoder.enable_pin_change();
    right_encoder.enable_pin_change();
}

void loop() {
    static uint32_t last;
    const uint32_t now = micros();
    const MotorMode mode = now < 30000UL ? MotorMode::DRIVE : now < 60000UL ? MotorMode::BRAKE : MotorMode::COAST;
    board.drive(0, 1000, mode);
    board.drive(1, -400, mode);
    if (now - last >= 10000UL) {
        last = now;
        int32_t counts[2];
        board.read_encoders(counts);
        uint8_t r[10];
        memcpy(r, counts, 8);
        r[8] = TCCR4A;
        r[9] = OCR4BL;
        report(r, 10);
    }
}
"""
)
BTS_PINS = {"L_RPWM": "E4", "L_LPWM": "E5", "L_REN": "A0", "L_LEN": "A1", "R_RPWM": "H3", "R_REN": "A2", "R_LEN": "A3"}


def test_mega_bts7960_and_pin_change_encoders(sim_pins: Path, tmp_path: Path) -> None:
    build = _build(_write_sketch(tmp_path, "Bts7960Hal", MEGA_BTS7960_SKETCH), "mega2560", tmp_path / "out")
    # Both encoders on one pin-change vector, some edges at the same instant. Port B (pins 50..53,
    # PCINT0_vect) rather than the example's port K (A8..A11, PCINT2_vect): simavr 1.6 does not
    # model pin-change interrupts on port K. The code path is the same, only the mask register
    # and the vector differ.
    schedule = _by_time(quadrature("B3", "B2", 5_000, [1] * 150), quadrature("B1", "B0", 5_000, [-1] * 80, step_us=100))
    run = simulate(sim_pins, build, 90_000, [*BTS_PINS.values(), "H4"], schedule)

    def levels(at_us: int) -> dict[str, int]:
        return {name: run.level(pin, at_us) for name, pin in BTS_PINS.items()}

    # Driving: left forward at full duty (RPWM high), right reverse on LPWM (pin 7, on the timer).
    assert levels(25_000) == {"L_RPWM": 1, "L_LPWM": 0, "L_REN": 1, "L_LEN": 1, "R_RPWM": 0, "R_REN": 1, "R_LEN": 1}
    assert levels(55_000) == {"L_RPWM": 0, "L_LPWM": 0, "L_REN": 1, "L_LEN": 1, "R_RPWM": 0, "R_REN": 1, "R_LEN": 1}
    assert levels(85_000) == dict.fromkeys(BTS_PINS, 0)
    assert run.level("H4", 85_000) == 0

    reports = run.records(10)
    assert len(reports) >= 8, run.uart.hex()
    assert reports[1][8] & 0b00100000  # COM4B1: pin 7 on the timer while driving
    assert reports[1][9] == 102  # 400 permille of 255, rounded
    assert reports[-1][8] & 0b00100000 == 0
    counts = (
        int.from_bytes(reports[-1][0:4], "little", signed=True),
        int.from_bytes(reports[-1][4:8], "little", signed=True),
    )
    assert counts == (150, -80)


# The examples themselves, booted: the core over each board, nothing connected to the host side.
BOOT_WATCH = {
    # example: (pins that must hold the safe state when disarmed, their levels, registers to dump)
    "AckermannPiCar": ({"B1": None, "B2": None}, ["@0x80", "@0x88", "@0x89", "@0x8A", "@0x8B"]),
    # BRAKE: IN1 = IN2 = high on both channels, STBY high.
    "DiffDriveTB6612": ({"A0": 1, "A1": 1, "A2": 1, "A3": 1, "A4": 1}, []),
    # RAMP_DOWN, then COAST: both PWM low, enables low.
    "DiffDriveBTS7960": ({"E4": 0, "E5": 0, "H3": 0, "H4": 0, "A0": 0, "A1": 0, "A2": 0, "A3": 0}, []),
}


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_boots_on_a_simulated_mcu(
    sim_pins: Path, example_builds: dict[str, firmware.BuildResult], name: str
) -> None:
    result = example_builds[name]
    profile = next(p for p in PROFILES.values() if p.example == name)
    pins, registers = BOOT_WATCH[name]
    run = subprocess.run(
        [str(sim_pins), result.board.mcu, str(result.elf), "300000", *pins, *registers],
        input="",
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    lines = run.stdout.splitlines()
    uart = next(line.split()[1] for line in lines if line.startswith("UART "))
    decoder = FrameDecoder()
    frames = [e for e in decoder.feed(bytes.fromhex(uart)) if isinstance(e, Frame)]
    assert decoder.stats.frames_ok == len(frames) > 0 and decoder.stats.crc_errors == 0, decoder.stats

    identity = frames[0].message
    assert isinstance(identity, messages.Identity), frames[0]
    assert identity.board == profile.board
    assert identity.capabilities == profile.capabilities
    feedback = [f.message for f in frames if isinstance(f.message, messages.Feedback)]
    period_ms = 1000 // profile.config.feedback_hz
    assert len(feedback) >= 250 // period_ms, f"{len(feedback)} FEEDBACK in 0.3 s at {profile.config.feedback_hz} Hz"
    assert all(f.boot_id == identity.boot_id for f in feedback)

    levels: dict[str, int] = {}
    regs: dict[int, int] = {}
    for line in lines:
        words = line.split()
        if words[:1] == ["PIN"]:
            levels[words[2]] = int(words[3])
        elif words[:1] == ["REG"]:
            regs[int(words[1], 0)] = int(words[2])
    expected = {pin: level for pin, level in pins.items() if level is not None}
    assert {pin: levels.get(pin, 0) for pin in expected} == expected
    if name == "AckermannPiCar":
        # Disarmed: ESC at neutral, steering at centre, both from Timer1 in hardware.
        cfg = profile.config
        centre_us = cfg.servo_min_us + cfg.steering_center_cdeg * (cfg.servo_max_us - cfg.servo_min_us) // 18000
        assert regs[0x80] & 0b10100000 == 0b10100000  # both channels on the timer
        assert regs[0x88] | regs[0x89] << 8 == 2 * cfg.esc_neutral_us - 1
        assert regs[0x8A] | regs[0x8B] << 8 == 2 * centre_us - 1
