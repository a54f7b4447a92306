"""The C++ generator's checks on what the real spec does not use yet, compiled and run natively.

The spec gets one more message, PROBE (an enum with gaps, negative and float ranges, a flags mask
with gaps, a variable-length char field); the C++ emitter writes the protocol for it into a
temporary library tree next to the real codec runtime, and tests/firmware/native/probe_checks.cpp runs the
cases against it with ASan and UBSan.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from protocol.generator import loader
from protocol.generator.emit import cpp

ROOT = Path(__file__).resolve().parents[3]
SPEC = ROOT / "protocol" / "spec" / "roverlink.toml"

PROBE = """
[[enums]]
name = "ProbeKind"
base = "u8"
doc = "Values with gaps."
values = [
  { name = "THREE", value = 3, doc = "." },
  { name = "SEVEN", value = 7, doc = "." },
  { name = "TEN", value = 10, doc = "." },
  { name = "TWELVE", value = 12, doc = "." },
]

[[enums]]
name = "ProbeBits"
base = "u16"
flags = true
doc = "Bits with gaps."
values = [
  { name = "BIT_0", value = 0x0001, doc = "." },
  { name = "BIT_2", value = 0x0004, doc = "." },
  { name = "BIT_8", value = 0x0100, doc = "." },
]

[[messages]]
id = 0x3E
name = "PROBE"
direction = "host_to_mcu"
delivery = "telemetry"
doc = "Exercises the generated checks."
fields = [
  { name = "e", type = "ProbeKind", doc = "." },
  { name = "s", type = "i16", min = -300, max = -100, doc = "." },
  { name = "f", type = "f32", min = -1.5, max = 2.5, doc = "." },
  { name = "flags", type = "ProbeBits", doc = "." },
  { name = "text", type = "char[..4]", doc = "." },
]

[[messages]]
id = 0x3F
name = "PROBE_REQUEST"
direction = "host_to_mcu"
delivery = "reliable"
doc = "A reliable request: its values are left to check_ranges(), which the firmware answers."
fields = [
  { name = "n", type = "u8", max = 9, doc = "." },
  { name = "e", type = "ProbeKind", doc = "." },
  { name = "flags", type = "ProbeBits", doc = "." },
]
"""


def _probe_spec_text() -> str:
    text = SPEC.read_text(encoding="utf-8")
    # Enums and messages are arrays of tables: the probe's go right before the state machine.
    at = text.index("[state_machine]")
    return text[:at] + PROBE + "\n" + text[at:]


@pytest.mark.skipif(shutil.which("g++") is None, reason="needs g++")
def test_generated_checks_on_a_probe_message(tmp_path: Path) -> None:
    spec = loader.parse(_probe_spec_text(), "probe.toml")
    src = tmp_path / "src"
    (src / "generated").mkdir(parents=True)
    for runtime in ("wire", "codec"):
        (src / runtime).symlink_to(ROOT / "arduino" / "RoverLink" / "src" / runtime)
    for name, text in cpp.emit(spec).items():
        if name.startswith(cpp.LIB):
            (src / "generated" / Path(name).name).write_text(text, encoding="utf-8")
    sources = [
        ROOT / "tests" / "firmware" / "native" / "probe_checks.cpp",
        src / "generated" / "roverlink_protocol.cpp",
    ]
    for runtime in ("wire", "codec"):
        sources += sorted((ROOT / "arduino" / "RoverLink" / "src" / runtime).glob("*.cpp"))
    exe = tmp_path / "probe_checks"
    flags = ["-std=c++11", "-Wall", "-Wextra", "-Werror", "-O1", "-g"]
    flags += ["-fsanitize=address,undefined", "-fno-sanitize-recover=all"]
    subprocess.run(["g++", *flags, f"-I{src}", *map(str, sources), "-o", str(exe)], check=True)
    run = subprocess.run([str(exe)], check=False, capture_output=True, text=True, timeout=60)
    print(run.stdout)
    assert run.returncode == 0, run.stdout + run.stderr
    counts = re.search(r"(\d+) passed, (\d+) failed", run.stdout)
    assert counts is not None and int(counts.group(1)) > 280 and counts.group(2) == "0"
