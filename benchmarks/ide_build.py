"""Flash of each example built as the Arduino IDE builds it, against `roverlink firmware build`.

    python3 benchmarks/ide_build.py            # needs Debian's arduino-builder (apt install arduino-builder)

The IDE's flags are the core's platform.txt as it stands (-Os and LTO, none of the size flags of
`roverlink firmware build`); both use the same avr-gcc and Arduino core, and the IDE route gets
the one define Debian's core lacks (-DDECIMAL_DIG=17, docs/firmware.md). Each example is built for
its own board, and arduino-builder's "Sketch uses N bytes" line is read.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from roverlink import firmware  # noqa: E402

# arduino-builder needs a ctags pattern, which the IDE's own platform.txt gives and Debian's core lacks.
CTAGS = (
    '"{path}/arduino-ctags" -u --language-force=c++ -f - --c++-kinds=svpf --fields=KSTtzns '
    '--line-directives "{source_file}"'
)
FQBN = {"uno": "arduino:avr:uno", "mega2560": "arduino:avr:mega:cpu=atmega2560"}
_USES = re.compile(r"Sketch uses (\d+) bytes")


def ide_flash(example: str, board: str, build: Path) -> int:
    """Bytes of flash arduino-builder reports for the example's sketch."""
    tools = firmware.Toolchain.find()
    build.mkdir(parents=True, exist_ok=True)
    sketch = firmware.example_dir(example) / f"{example}.ino"
    args = ["arduino-builder", "-compile", "-hardware", str(tools.core_dir.parents[1]), "-tools", "/usr/bin"]
    args += ["-fqbn", FQBN[board], "-libraries", str(ROOT / "arduino"), "-build-path", str(build)]
    args += ["-prefs", "compiler.cpp.extra_flags=-DDECIMAL_DIG=17", "-prefs", "tools.ctags.path=/usr/bin"]
    args += ["-prefs", f"tools.ctags.pattern={CTAGS}", str(sketch)]
    run = subprocess.run(args, capture_output=True, text=True, timeout=600, check=False)
    found = _USES.search(run.stdout)
    if run.returncode != 0 or found is None:
        raise SystemExit(f"arduino-builder failed on {example}:\n{run.stdout}{run.stderr}")
    return int(found[1])


def main() -> int:
    if shutil.which("arduino-builder") is None:
        print("arduino-builder is not installed: apt install arduino-builder", file=sys.stderr)
        return 2
    print("| example | `roverlink firmware build` | Arduino IDE flags (`arduino-builder`) | difference |")
    print("|---|---|---|---|")
    with tempfile.TemporaryDirectory(prefix="roverlink-ide-") as tmp:
        for example in sorted(firmware.examples()):
            board = firmware.example_board(example).name
            ours = firmware.build_example(example, out_dir=Path(tmp) / "ours" / example).flash_used
            ide = ide_flash(example, board, Path(tmp) / "ide" / example)
            print(f"| {example} ({board}) | {ours:,} B | {ide:,} B | {ide - ours:+,} B |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
