"""The Pico firmware (roverlink/firmware/pico.py): every reference robot moved to the Pico pinout
builds with Debian's arm-none-eabi-gcc into a flash image whose boot block carries the CRC the boot
ROM checks and a UF2 a Pico takes; the image boots in rp2040js through that boot block and
announces itself as a Pico; a corrupted boot block is refused as the boot ROM would."""

from __future__ import annotations

import struct
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from emulator.backends.rp2040 import Harness, Rp2040Error, Rp2040Robot, pico_profile, pico_robot
from protocol.framing import Frame, FrameDecoder
from protocol.generated.enums import Board, Capability, IdentityReason
from protocol.generated.messages import Identity
from protocol.robotfile import REFERENCES
from roverlink.commands.robot import PICO_FLASH
from roverlink.firmware.pico import BOOT2_BYTES, FLASH_BASE, PicoBuild, _boot2, _tool, build_pico, crc32_boot2
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
    estimates = {robot: size for robot, size in PICO_FLASH.values()}  # what `roverlink robot show` says
    assert abs(estimates[name] - built.flash_used) <= 0.02 * built.flash_used, (name, built.flash_used)
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


def test_a_hung_firmware_is_reset_by_the_watchdog_and_boots_with_a_new_boot_id(tmp_path: Path) -> None:
    """The loop stops while the motors are driven (a firmware stuck with its interrupts off): the
    motors stay driven until the watchdog resets the chip 100 ms later; the board then boots again,
    puts the motors in the robot's safe state (BRAKE) and announces a new boot_id."""
    from host_sdk.framing import encode_frame
    from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
    from protocol.generated.hardware import MotorMode
    from protocol.generated.messages import Arm, Feedback, Hello, SetWheelSpeeds

    built = _build("diffdrive-tb6612", tmp_path)
    decoder = FrameDecoder()

    def received(robot: Rp2040Robot) -> list[object]:
        return [f.message for f in decoder.feed(robot.host_read()) if isinstance(f, Frame)]

    with Rp2040Robot(pico_profile("diffdrive-tb6612"), built.bin) as robot:
        robot.advance_us(20_000)
        [boot, *_] = received(robot)
        assert isinstance(boot, Identity)
        robot.host_write(encode_frame(Hello(PROTOCOL_VERSION, SPEC_HASH, 0, 0, 0), seq=1))
        robot.advance_us(20_000)
        robot.host_write(encode_frame(Arm(boot.boot_id), seq=2))
        robot.advance_us(20_000)
        for seq in range(3, 13):
            robot.host_write(encode_frame(SetWheelSpeeds(200, 200), seq=seq))
            robot.advance_us(10_000)
        received(robot)
        assert robot.pins.mode == (MotorMode.DRIVE, MotorMode.DRIVE)
        robot.harness.hang()
        robot.advance_us(90_000)
        assert robot.harness.resets == 0 and robot.pins.mode == (MotorMode.DRIVE, MotorMode.DRIVE)
        assert received(robot) == []  # nothing from a hung firmware
        robot.advance_us(30_000)  # the watchdog's 100 ms are over
        assert robot.harness.resets == 1
        assert robot.pins.mode == (MotorMode.BRAKE, MotorMode.BRAKE) and robot.pins.duty == (0.0, 0.0)
        robot.advance_us(20_000)
        again = [m for m in received(robot) if isinstance(m, Identity)]
    assert [m.reason for m in again] == [IdentityReason.BOOT]
    assert again[0].boot_id != boot.boot_id
    assert not any(isinstance(m, Feedback) for m in again)


def test_the_picos_frame_decoder_is_within_the_avr_budget(tmp_path: Path) -> None:
    """docs/budgets.md, RP2040: the decoder's cycles per byte of frame in rp2040js (deterministic)
    within the AVR decoder's bound, every SET_PID of a one-second flood answered, and the whole
    frame's cost (interrupt, decode, dispatch, the gains applied, the ACK) within its bound."""
    from benchmarks.rp2040 import DECODER_BUDGET, WHOLE_FRAME_BUDGET, measure

    built = _build("diffdrive-tb6612", tmp_path)
    run = measure(115_200, built.bin, built.elf)
    print(f"\n  decoder {run.decoder_cycles_per_byte} cycles/byte, whole frame {run.whole_frame_cycles_per_byte}")
    assert 0 < run.decoder_cycles_per_byte <= DECODER_BUDGET
    assert run.decoder_cycles_per_byte < run.whole_frame_cycles_per_byte <= WHOLE_FRAME_BUDGET
    assert run.frames > 400  # the line was kept full: 27-byte frames at 115200 baud


def test_roverlink_firmware_builds_and_flashes_a_pico_robot_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """`roverlink firmware build --robot FILE` for a board = "pico" file writes the ELF, the flash
    image and the UF2; `flash` copies the UF2 to the Pico's BOOTSEL drive (here a folder with the
    boot ROM's INFO_UF2.TXT), refuses a folder that is not one, and says how to get the drive."""
    from protocol.robotfile import reference_path
    from protocol.robotfile.pico import on_pico
    from tests.support.avr_build import firmware_cli

    _require()
    monkeypatch.chdir(tmp_path)  # flash builds where the user is: ./firmware/<name>/pico
    path = tmp_path / "my_pico.toml"
    path.write_text(on_pico(reference_path("diffdrive-bts7960").read_text(encoding="utf-8")), encoding="utf-8")
    out = tmp_path / "out"
    code, stdout, _ = firmware_cli(capsys, "firmware", "build", "--robot", str(path), "--out", str(out))
    assert code == 0 and "my_pico (pico): flash" in stdout
    assert {p.name for p in out.iterdir()} >= {"my_pico.elf", "my_pico.bin", "my_pico.uf2", "robot_profile.h"}
    drive = tmp_path / "RPI-RP2"
    drive.mkdir()
    code, _, err = firmware_cli(capsys, "firmware", "flash", "--robot", str(path), "--drive", str(drive))
    assert code == 2 and "not a Pico's BOOTSEL drive" in err
    (drive / "INFO_UF2.TXT").write_text("UF2 Bootloader v3.0\nModel: Raspberry Pi RP2\nBoard-ID: RPI-RP2\n")
    code, stdout, _ = firmware_cli(capsys, "firmware", "flash", "--robot", str(path), "--drive", str(drive))
    assert code == 0 and (drive / "my_pico.uf2").read_bytes()[:4] == b"UF2\n"
    assert (out / "my_pico.uf2").stat().st_mode & 0o777 == 0o644  # as the compiler writes its files
    code, stdout, _ = firmware_cli(
        capsys, "firmware", "flash", "--robot", str(path), "--drive", str(drive), "--dry-run"
    )
    assert code == 0 and f"# copy {tmp_path}/firmware/my_pico/pico/my_pico.uf2 to {drive}" in stdout
    code, _, err = firmware_cli(capsys, "firmware", "flash", "--robot", str(path), "--drive", str(tmp_path / "no"))
    assert code == 2 and "no such folder" in err
    code, _, err = firmware_cli(capsys, "firmware", "flash", "--robot", str(path), "--port", "/dev/ttyACM0")
    assert code == 2 and "--port /dev/ttyACM0: a Pico is flashed through its BOOTSEL drive" in err


def test_builds_at_once_into_one_fresh_cache_each_get_a_whole_boot_block(tmp_path: Path) -> None:
    """Test workers build side by side: each build's intermediate files are its own, and only the
    finished boot block is published (two once met in one half-written object)."""
    _require()
    gcc, objcopy = _tool("gcc"), _tool("objcopy")
    with ThreadPoolExecutor(max_workers=6) as pool:
        objects = list(pool.map(lambda _: _boot2(tmp_path, gcc, objcopy).read_bytes(), range(6)))
    assert len(set(objects)) == 1 and len(objects[0]) > BOOT2_BYTES
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        f"boot2.{_boot2(tmp_path, gcc, objcopy).name.split('.')[1]}.o"
    ]
