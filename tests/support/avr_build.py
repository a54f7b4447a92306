"""Building Arduino sketches with the `roverlink firmware` tool in tests (tests/firmware)."""

from __future__ import annotations

from pathlib import Path

import pytest

from protocol.generated.profiles import PROFILES
from roverlink import firmware
from roverlink.cli import main as cli_main

ROOT = Path(__file__).resolve().parents[2]
LIBRARY = ROOT / "arduino" / "RoverLink"
EXAMPLES = sorted(profile.example for profile in PROFILES.values())


def require_toolchain() -> None:
    try:
        firmware.Toolchain.find()
    except firmware.ToolchainMissingError as exc:
        pytest.fail(f"{exc} (scripts/test.sh installs them)", pytrace=False)


def build_sketch(sketch: Path, board: str, out: Path) -> firmware.BuildResult:
    try:
        return firmware.build_sketch(sketch, board, out)
    except firmware.CompileError as exc:
        error = exc
    pytest.fail(f"{sketch.name} does not build for {board}:\n{error}", pytrace=False)


def write_sketch(root: Path, name: str, text: str) -> Path:
    sketch = root / name
    sketch.mkdir(parents=True, exist_ok=True)
    (sketch / f"{name}.ino").write_text(text, encoding="utf-8")
    return sketch


def report(record_property: pytest.RecordProperty, result: firmware.BuildResult) -> None:
    print(f"\n  {result.summary()}")
    record_property(f"{result.name}.{result.board.name}.flash_bytes", result.flash_used)
    record_property(f"{result.name}.{result.board.name}.sram_bytes", result.sram_used)


def firmware_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """`roverlink ARGV` in-process: (exit status, stdout, stderr)."""
    try:
        code = cli_main(list(argv))
    except SystemExit as exc:  # argparse's own errors
        code = int(exc.code or 0)
    out, err = capsys.readouterr()
    return code, out, err
