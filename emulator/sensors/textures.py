"""The photo look's materials: greyscale photographs (and one procedural texture) as luminance maps.

Each material is a TEXELS x TEXELS map of luminance factors (mean 1, its contrast scaled), tiled by
mirroring (so the photographs' edges never show a seam) at `texel_m` metres per texel. Every map is
kept at LEVELS blurs, a poor man's mipmap: a pixel covering many texels reads a blurred level, so
far walls and the far floor do not alias into noise. The photographs ship in textures/ (their
sources and licences: textures/README.md); a missing one is a TextureMissingError that names it.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from emulator.errors import EmulatorError
from protocol.errors import import_optional

TEXTURE_DIR = Path(__file__).resolve().parent / "textures"
TEXELS = 256
"""Side of every map (a power of two: the mirrored tiling is a bit mask)."""
_SHIFT = TEXELS.bit_length() - 1
LEVELS = 3
BLUR_TEXELS = (0.0, 1.5, 4.0)
"""Gaussian sigma of each level."""


class TextureMissingError(EmulatorError, FileNotFoundError):
    """A texture file of the photo look is not where the emulator's package data should be."""

    def __init__(self, name: str, path: Path) -> None:
        self.path = path
        super().__init__(
            f"camera texture {name!r} is missing ({path}): the photo look needs the emulator's package "
            "data (emulator/sensors/textures/); reinstall RoverLink or use look=plain"
        )


@dataclass(frozen=True, slots=True)
class Material:
    name: str
    source: str
    """A PNG in TEXTURE_DIR, or "" for the procedural texture."""
    texel_m: float
    contrast: float
    """1: the photograph's own contrast; less flattens it."""


MATERIALS = (
    Material("brick", "brick.png", 0.0028, 1.0),  # walls: 6.5 cm courses
    Material("card", "", 0.005, 0.6),  # boxes: painted cardboard
    Material("grass", "grass.png", 0.003, 0.8),  # cylinders: potted hedges
    Material("fabric", "gravel.png", 0.002, 0.3),  # the target (and its look-alikes): coarse weave
    Material("gravel", "gravel.png", 0.006, 0.7),  # the floor
)
WALL, BOX, CYLINDER, TARGET, FLOOR = range(len(MATERIALS))


def load_textures(directory: Path | None = None) -> NDArray[np.float32]:
    """(materials, LEVELS, TEXELS, TEXELS) luminance factors, read once per directory."""
    return _load(directory or TEXTURE_DIR)


@functools.cache
def _load(directory: Path) -> NDArray[np.float32]:
    cv2 = import_optional("cv2", "vision", "the emulated camera")
    out = np.empty((len(MATERIALS), LEVELS, TEXELS, TEXELS), dtype=np.float32)
    for m, material in enumerate(MATERIALS):
        base = _procedural() if not material.source else _read(cv2, directory, material.source)
        lum = 1.0 + material.contrast * (base / base.mean() - 1.0)
        for level, sigma in enumerate(BLUR_TEXELS):
            blurred = lum if sigma == 0 else cv2.GaussianBlur(lum, (0, 0), sigma, borderType=cv2.BORDER_REFLECT)
            out[m, level] = blurred
    out.setflags(write=False)
    return out


def _read(cv2: object, directory: Path, name: str) -> NDArray[np.float32]:
    path = directory / name
    image = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE) if path.is_file() else None  # type: ignore[attr-defined]
    if image is None:
        raise TextureMissingError(name, path)
    if image.shape != (TEXELS, TEXELS):
        image = cv2.resize(image, (TEXELS, TEXELS), interpolation=cv2.INTER_AREA)  # type: ignore[attr-defined]
    return np.asarray(image, dtype=np.float32)


def _procedural() -> NDArray[np.float32]:
    """Painted cardboard: blotches plus fine grain, from a fixed seed (PCG64's normals are the same
    on every machine)."""
    cv2 = import_optional("cv2", "vision", "the emulated camera")
    noise = np.random.default_rng(20_261_127).standard_normal((TEXELS, TEXELS)).astype(np.float32)
    blotches = cv2.GaussianBlur(noise, (0, 0), 12.0, borderType=cv2.BORDER_REFLECT)
    grain = cv2.GaussianBlur(noise, (0, 0), 1.0, borderType=cv2.BORDER_REFLECT)
    tex = 128.0 + 40.0 * blotches / blotches.std() + 12.0 * grain / grain.std()
    return np.asarray(np.clip(tex, 1.0, 255.0), dtype=np.float32)


def mirrored(coord: NDArray[np.float32]) -> NDArray[np.int32]:
    """Texel index of a texture coordinate, the map tiled by mirroring (period 2 * TEXELS)."""
    i = np.floor(coord).astype(np.int32) & (2 * TEXELS - 1)
    return np.asarray(i ^ ((i >> _SHIFT) * (2 * TEXELS - 1)), dtype=np.int32)


def level_for(texels_per_pixel: NDArray[np.float32]) -> NDArray[np.int32]:
    """The blur level for a pixel covering that many texels."""
    return ((texels_per_pixel > 1.5).astype(np.int32) + (texels_per_pixel > 4.0)).astype(np.int32)


def sample(
    flat: NDArray[np.float32],
    material: NDArray[np.int64] | np.int64,
    level: NDArray[np.int32],
    v: NDArray[np.float32],
    u: NDArray[np.float32],
) -> NDArray[np.float32]:
    """Luminance factors at texture coordinates (v: rows, u: columns, in texels) of each pixel's
    material and level (`flat`: load_textures() flattened), interpolated between the four nearest
    texels (nearest-texel sampling turns a close surface into blocks)."""
    v0, u0 = np.floor(v), np.floor(u)
    fv, fu = v - v0, u - u0
    base = (material * LEVELS + level) * TEXELS
    row0, row1 = (base + mirrored(v0)) * TEXELS, (base + mirrored(v0 + 1)) * TEXELS
    col0, col1 = mirrored(u0), mirrored(u0 + 1)
    top = np.take(flat, row0 + col0) * (1 - fu) + np.take(flat, row0 + col1) * fu
    bottom = np.take(flat, row1 + col0) * (1 - fu) + np.take(flat, row1 + col1) * fu
    return np.asarray(top * (1 - fv) + bottom * fv, dtype=np.float32)
