"""The Pico firmware (roverlink/firmware/pico.py): every reference robot moved to the Pico pinout
builds with Debian's arm-none-eabi-gcc into a flash image whose boot block carries the CRC the boot
ROM checks and a UF2 a Pico takes; the image boots in rp2040js through that boot block and
announces itself as a Pico; a corrupted boot block is refused as the boot ROM would."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from emulator.backends.rp2040 import Harness, Rp2040Error, Rp2040Robot, pico_profile, pico_robot
from protocol.framing import Frame, FrameDecoder
from protocol.generated.enums import Board, Capability, IdentityReason
from protocol.generated.messages import Identity
from protocol.robotfile import REFERENCES
from roverlink.firmware.pico import BOOT2_BYTES, FLASH_BASE, PicoBuild, build_pico, crc32_boot2
from tests.firmware.test_rp2040_harness import _require


def _build(name: str, tmp_path: Path) -> PicoBuild:
    _require()
    return build_pico(pico_robot(name), tmp_path / name, name=name)


def test_the_boot_blocks_crc_is_the_boot_roms() -> None:
    assert crc32_boot2(b"123456789") == 0x0376E6E7  # CRC-32/MPEG-2's check value


@pytest.mark.parametrize("name", REFERENCES)
def test_each_reference_robot_builds_a_flash_image_and_a_uf2(name: str, tmp_path: Path) -> None:
    built = _build(name, tmp_path)
    image = built.bin.read_bytes()
    assert built.flash_used == len(image) and 10_000 < len(image) < 64_000
    body, (crc,) = image[: BOOT2_BYTES - 4], struct.unpack("<I", image[BOOT2_BYTES - 4 : BOOT2_BYTES])
    assert crc == crc32_boot2(body)
    sp, reset = struct.unpack("<II", image[BOOT2_BYTES : BOOT2_BYTES + 8])  # the vector table after it
    assert sp == 0x20040000 and FLASH_BASE + BOOT2_BYTES < reset < FLASH_BASE + len(image) and reset & 1
    uf2 = built.uf2.read_bytes()
    blocks = [uf2[i : i + 512] for i in range(0, len(uf2), 512)]
    assert len(blocks) == -(-len(image) // 256)
    payload = b""
    for n, block in enumerate(blocks):
        magic0, magic1, flags, address, size, number, total, family = struct.unpack("<8I", block[:32])
        assert (magic0, magic1, struct.unpack("<I", block[508:])[0]) == (0x0A324655, 0x9E5D5157, 0x0AB16F30)
        assert (flags, address, size, number, total, family) == (
            0x2000,
            FLASH_BASE + 256 * n,
            256,
            n,
            len(blocks),
            0xE48BFF56,
        )
        payload += block[32 : 32 + size]
    assert payload[: len(image)] == image


def test_the_image_boots_through_its_boot_block_as_a_pico(tmp_path: Path) -> None:
    built = _build("diffdrive-tb6612", tmp_path)
    with Rp2040Robot(pico_profile("diffdrive-tb6612"), built.bin) as robot:
        robot.advance_us(50_000)
        frames = [f for f in FrameDecoder().feed(robot.host_read()) if isinstance(f, Frame)]
    ident = frames[0].message
    assert isinstance(ident, Identity) and ident.reason is IdentityReason.BOOT
    assert ident.board is Board.PICO and ident.robot_name == "diffdrive-tb6612"
    assert not ident.capabilities & Capability.EEPROM  # the Pico keeps no configuration
    assert ident.capabilities & Capability.DIFF_DRIVE and ident.capabilities & Capability.TURN_SIGNALS


def test_a_corrupted_boot_block_is_refused(tmp_path: Path) -> None:
    built = _build("picar", tmp_path)
    image = bytearray(built.bin.read_bytes())
    image[10] ^= 0x01
    bad = tmp_path / "bad.bin"
    bad.write_bytes(bytes(image))
    with pytest.raises(Rp2040Error):
        Harness(bad, flash=True)
