"""The machine: its distribution, its board (a Raspberry Pi, a Jetson and its JetPack) and Python."""

from __future__ import annotations

import re
import sys
from dataclasses import dataclass
from pathlib import Path

JETPACK_OF_L4T = {"32": "4", "34": "5", "35": "5", "36": "6"}
"""JetPack's major version from L4T's release (/etc/nv_tegra_release: "# R36 (release), ...")."""


@dataclass(frozen=True, slots=True)
class Machine:
    os_id: str
    """/etc/os-release's ID: debian, ubuntu, raspbian, ... ("" when unknown)."""
    os_version: str
    os_name: str
    board: str | None
    """/proc/device-tree/model: "Raspberry Pi 5 Model B Rev 1.0", "NVIDIA Jetson Orin Nano ..."."""
    l4t: str | None
    """A Jetson's L4T release ("36.3.0"), None elsewhere."""

    @property
    def kind(self) -> str:
        """raspberry-pi, jetson, ubuntu, debian or other: what decides the install route."""
        if self.l4t is not None or (self.board or "").startswith("NVIDIA Jetson"):
            return "jetson"
        if (self.board or "").startswith("Raspberry Pi"):
            return "raspberry-pi"
        return self.os_id if self.os_id in ("ubuntu", "debian") else "other"

    @property
    def jetpack(self) -> str | None:
        return None if self.l4t is None else JETPACK_OF_L4T.get(self.l4t.split(".")[0])


@dataclass(frozen=True, slots=True)
class PythonInfo:
    version: tuple[int, int, int]
    executable: str
    venv: bool
    system_site_packages: bool
    """In a venv, whether it sees the base interpreter's packages (made with --system-site-packages)."""
    base_executable: str
    """The interpreter the venv was made from (this one outside a venv)."""

    @property
    def text(self) -> str:
        return ".".join(str(n) for n in self.version)


def _read(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ""


def machine(root: Path = Path("/")) -> Machine:
    release = dict(re.findall(r'^(\w+)="?([^"\n]*)"?$', _read(root / "etc" / "os-release"), re.M))
    board = _read(root / "proc" / "device-tree" / "model").strip("\0\n ") or None
    tegra = re.search(r"R(\d+)\s*\(release\),\s*REVISION:\s*([\d.]+)", _read(root / "etc" / "nv_tegra_release"))
    l4t = f"{tegra.group(1)}.{tegra.group(2)}" if tegra else None
    return Machine(
        release.get("ID", ""), release.get("VERSION_ID", ""), release.get("PRETTY_NAME", "unknown"), board, l4t
    )


def python_info() -> PythonInfo:
    venv = sys.prefix != sys.base_prefix
    cfg = _read(Path(sys.prefix) / "pyvenv.cfg") if venv else ""
    system = re.search(r"^include-system-site-packages\s*=\s*true", cfg, re.M | re.I) is not None
    home = re.search(r"^home\s*=\s*(.+)$", cfg, re.M)
    base = sys.executable
    if venv and home:
        base = str(Path(home.group(1).strip()) / f"python{sys.version_info.major}.{sys.version_info.minor}")
    major, minor, micro = sys.version_info[:3]
    return PythonInfo((major, minor, micro), sys.executable, venv, system, base)
