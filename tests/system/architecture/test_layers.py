"""The package floors: which package may import which (docs/architecture.md).

    protocol        the wire: imports none of the others
    host_sdk        robot code's API: imports protocol only
    emulator        the firmware model, plant and world: imports protocol only
    roverlink       the command's tools: may import all three

Every import statement is read from the source (module level, inside functions, and under
TYPE_CHECKING alike), so a lazy import cannot hide an arrow running the wrong way.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
PACKAGES = ("protocol", "host_sdk", "emulator", "roverlink")
MAY_IMPORT = {
    "protocol": {"protocol"},
    "host_sdk": {"protocol", "host_sdk"},
    "emulator": {"protocol", "emulator"},
    "roverlink": {"protocol", "host_sdk", "emulator", "roverlink"},
}


def imported_packages(source: str) -> list[tuple[int, str]]:
    """(line, top-level package) of every import of one of PACKAGES in `source`."""
    found = []
    for node in ast.walk(ast.parse(source)):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names = [node.module]
        for name in names:
            top = name.split(".")[0]
            if top in PACKAGES:
                found.append((node.lineno, top))
    return found


def violations(package: str, root: Path = ROOT) -> list[str]:
    out = []
    for path in sorted((root / package).rglob("*.py")):
        for line, top in imported_packages(path.read_text(encoding="utf-8")):
            if top not in MAY_IMPORT[package]:
                out.append(f"{path.relative_to(root)}:{line}: {package} imports {top}")
    return out


@pytest.mark.parametrize("package", PACKAGES)
def test_no_import_runs_against_the_floors(package: str) -> None:
    assert violations(package) == []


def test_the_check_sees_lazy_and_type_checking_imports(tmp_path: Path) -> None:
    pkg = tmp_path / "host_sdk"
    pkg.mkdir()
    (pkg / "a.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    from emulator import Emulator\n"
        "def f():\n    import roverlink.cli\n"
        "from protocol.framing import encode_frame\n"
    )
    assert violations("host_sdk", tmp_path) == [
        "host_sdk/a.py:3: host_sdk imports emulator",
        "host_sdk/a.py:5: host_sdk imports roverlink",
    ]


def test_importing_the_sdk_loads_no_emulator_and_no_tools() -> None:
    import subprocess
    import sys

    code = (
        "import sys, host_sdk, host_sdk.testing, host_sdk.transport;"
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in ('emulator', 'roverlink', 'hypothesis'));"
        "print(','.join(bad))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == ""


def test_importing_the_sdk_loads_asyncio_only_for_async_programs() -> None:
    import subprocess
    import sys

    code = "import sys, host_sdk; print('asyncio' in sys.modules); host_sdk.AsyncRobot; print('asyncio' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.split() == ["False", "True"]


def test_firmware_library_includes_run_one_way() -> None:
    """The Arduino library's folders: wire <- generated <- codec <- core, and hal beside core's
    foot; an #include never points up."""
    import re

    src = ROOT / "arduino" / "RoverLink" / "src"
    may_include = {
        "wire": {"wire"},
        "generated": {"wire", "generated"},
        "codec": {"wire", "generated", "codec"},
        "hal": {"wire", "generated", "hal"},
        "core": {"wire", "generated", "codec", "hal", "core"},
    }
    include = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
    bad = []
    for folder, allowed in may_include.items():
        for path in sorted((src / folder).rglob("*")):
            if path.suffix not in (".h", ".cpp"):
                continue
            for target in include.findall(path.read_text(encoding="utf-8")):
                resolved = (path.parent / target).resolve()
                try:
                    top = resolved.relative_to(src).parts[0]
                except ValueError:
                    continue  # a system or Arduino header
                if top not in allowed and resolved.exists():
                    bad.append(f"{path.relative_to(src)} includes {target}")
    assert bad == []


def test_protocol_layers_run_one_way() -> None:
    """Inside protocol: codec (COBS, CRC, message base) <- generated <- framing; the codec imports
    neither the generated messages nor the frame codec, the generated code not the frame codec."""
    below = {"codec": ("protocol.generated", "protocol.framing"), "generated": ("protocol.framing",)}
    bad = []
    for folder, forbidden in below.items():
        for path in sorted((ROOT / "protocol" / folder).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
                if isinstance(node, ast.ImportFrom) and node.module:
                    names = [node.module, *(f"{node.module}.{a.name}" for a in node.names)]
                bad += [f"{path.relative_to(ROOT)} imports {n}" for n in names if n.startswith(forbidden)]
    assert bad == []
