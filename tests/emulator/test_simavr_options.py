"""The simavr backend's options on the real firmware (the example's ELF in simavr), on virtual time:
--seed (boot_id from the seeded ADC noise and EEPROM boot counter), --eeprom saved, --bootloader-ms
and the host's view of a DTR reset, line faults and resets from a fault spec, and what the CLI
refuses. Builds the harness and the ELFs once (cached under build/simavr)."""

from __future__ import annotations

import pytest

from emulator.backends.simavr import SimavrError, SimavrRobot
from emulator.firmware.config import LoadResult
from host_sdk import messages
from host_sdk.framing import Frame, FrameDecoder, encode_frame
from protocol.codec.message import Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.enums import FeedbackMode, IdentityReason, NackReason
from roverlink.cli import main as roverlink_main
from tests.support.simavr import simavr_robot

PROFILE = "diffdrive-tb6612"


class Reader:
    def __init__(self, robot: SimavrRobot) -> None:
        self.robot = robot
        self.decoder = FrameDecoder()
        self.raw = b""
        self.frames: list[tuple[int, Message]] = []

    def pump(self) -> None:
        data = self.robot.host_read()
        self.raw += data
        for event in self.decoder.feed(data):
            if isinstance(event, Frame):
                self.frames.append((self.robot.now_us, event.message))

    def boots(self) -> list[tuple[int, messages.Identity]]:
        return [(t, m) for t, m in self.frames if isinstance(m, messages.Identity) and m.reason == IdentityReason.BOOT]

    def run_until_boots(self, n: int, timeout_us: int = 3_000_000) -> list[tuple[int, messages.Identity]]:
        def done() -> bool:
            self.pump()
            return len(self.boots()) >= n

        assert self.robot.run_until(done, timeout_us), f"{len(self.boots())} boots, wanted {n}"
        return self.boots()

    def logs(self) -> list[str]:
        return [m.text for _, m in self.frames if isinstance(m, messages.Log)]


@pytest.fixture(scope="module")
def built() -> None:
    try:
        simavr_robot(PROFILE).close()
    except SimavrError as exc:  # pragma: no cover
        pytest.fail(f"the simavr backend needs avr-gcc, the Arduino core and simavr (scripts/test.sh): {exc}")


def first_boot_id(seed: int | None, profile: str = PROFILE) -> int:
    with simavr_robot(profile, seed=seed) as robot:
        return Reader(robot).run_until_boots(1)[0][1].boot_id


@pytest.mark.usefixtures("built")
def test_seed_draws_the_boards_randomness() -> None:
    assert first_boot_id(3) == first_boot_id(3)
    ids = {first_boot_id(seed) for seed in (3, 4, 5)}
    assert len(ids) == 3
    assert first_boot_id(None) not in ids


@pytest.mark.usefixtures("built")
def test_eeprom_saved_boots_without_the_defaults_warning() -> None:
    with simavr_robot(PROFILE, seed=1) as blank, simavr_robot(PROFILE, seed=1, eeprom="saved") as saved:
        readers = [Reader(blank), Reader(saved)]
        for r in readers:
            r.run_until_boots(1)
            r.robot.advance_us(50_000)
            r.pump()
        assert readers[0].logs() == [LoadResult.NO_IMAGE.value]
        assert readers[1].logs() == []


@pytest.mark.usefixtures("built")
def test_dtr_reset_bootloader_as_the_python_emulator_models_it() -> None:
    with simavr_robot(PROFILE, seed=2, bootloader_ms=300) as robot:
        r = Reader(robot)
        r.run_until_boots(1)
        robot.advance_us(100_000)
        r.pump()
        errors_before = r.decoder.stats.cobs_errors + r.decoder.stats.crc_errors
        raw_before = len(r.raw)
        t_reset = robot.now_us
        robot.dtr_reset()
        robot.advance_us(50_000)
        hello = messages.Hello(PROTOCOL_VERSION, SPEC_HASH, 0, FeedbackMode.STREAM, 0)
        robot.host_write(encode_frame(hello, seq=0))  # lost: the MCU is in its bootloader
        boots = r.run_until_boots(2)
        t_boot, ident = boots[1]
        assert 300_000 <= t_boot - t_reset <= 400_000
        assert ident.boot_id != boots[0][1].boot_id
        assert robot.truth.boot_ids == (boots[0][1].boot_id, ident.boot_id)  # from before the line
        garbage = next(f.detail for f in robot.truth.faults if f.kind == "bootloader_garbage")
        assert r.raw[raw_before:].startswith(bytes.fromhex(garbage) + b"\x00")
        assert robot.truth.bytes_lost_in_reset > 0
        assert r.decoder.stats.cobs_errors + r.decoder.stats.crc_errors > errors_before  # the garbage
        robot.advance_us(100_000)
        r.pump()
        assert not [m for _, m in r.frames if isinstance(m, messages.Identity) and m.reason != IdentityReason.BOOT]


@pytest.mark.usefixtures("built")
def test_fault_spec_on_the_firmware() -> None:
    with simavr_robot("picar", seed=6, faults="bitflip.m2h=2e-3,reset@0.3", bootloader_ms=200) as robot:
        r = Reader(robot)
        robot.advance_us(1_000_000)
        r.pump()
        t = robot.truth
        assert t.mcu_to_host is not None and t.mcu_to_host.bits_flipped > 0
        assert r.decoder.stats.crc_errors + r.decoder.stats.cobs_errors > 0
        assert t.resets == 1 and [f.kind for f in t.faults if f.kind in ("reset", "bootloader_garbage")] == [
            "reset",
            "bootloader_garbage",
        ]
        boots = [t_us for t_us, m in r.boots()]
        assert boots and boots[-1] >= 500_000  # the second boot, after the bootloader
        # Ground truth, read before the line's bit flips: both boots, whatever the host lost.
        assert len(t.boot_ids) == 2 and t.boot_ids[0] != t.boot_ids[1]


@pytest.mark.usefixtures("built")
def test_cli_refuses_what_simavr_cannot_do(capsys: pytest.CaptureFixture[str]) -> None:
    assert roverlink_main(["emulate", "--backend", "simavr", "--faults", "bitflip=1e-4,eeprom@1"]) == 2
    err = capsys.readouterr().err
    assert "eeprom@1" in err and "simavr" in err and "EEPROM" in err
    assert roverlink_main(["emulate", "--backend", "simavr", "--baud", "57600"]) == 2
    err = capsys.readouterr().err
    assert "baud = 57600" in err and "Serial.begin(115200)" in err


@pytest.mark.usefixtures("built")
@pytest.mark.parametrize("drift_ppm", [-10_000, 10_000])
def test_drift_keeps_the_hosts_byte_pace(drift_ppm: int) -> None:
    """A drifting MCU clock still receives the host's bytes at the host's pace: after a 2 s flood,
    the last answer comes one frame after the last byte, not after a backlog (1 % of 2 s = 20 ms)."""
    with simavr_robot(PROFILE, seed=1, drift_ppm=drift_ppm) as robot:
        r = Reader(robot)
        r.run_until_boots(1)
        pid = messages.SetPid(255, 1.0, 6.0, 0.0, 1.5, 0.0)  # answered NACK(NO_SESSION) outside a session
        flood = b"".join(encode_frame(pid, seq=i % 256) for i in range(1000))
        t0 = robot.now_us
        robot.host_write(flood)
        flood_end = t0 + len(flood) * 10 * 1_000_000 // 115_200

        def answers() -> list[int]:
            r.pump()
            return [t for t, m in r.frames if isinstance(m, messages.Nack) and m.req_id == messages.SetPid.MSG_ID]

        assert robot.run_until(lambda: len(answers()) == 1000, 3_000_000), f"{len(answers())} of 1000 answered"
        # One request's bytes plus one NACK's at 115200 baud, and 2 ms of margin: far below a backlog.
        nack = messages.Nack(messages.SetPid.MSG_ID, 0, NackReason.NO_SESSION, 0)
        frame_us = (len(encode_frame(pid, seq=0)) + len(encode_frame(nack, seq=0))) * 87
        assert answers()[-1] - flood_end < frame_us + 2_000


@pytest.mark.usefixtures("built")
def test_harness_outlives_a_signal_to_its_owners_process_group() -> None:
    """Ctrl-C in a terminal, or systemd stopping a unit, signals every process of the group: the
    harness runs in a session of its own, so only its owner stops it, in order (close())."""
    import os

    with simavr_robot(PROFILE) as robot:
        assert os.getpgid(robot.harness.pid) != os.getpgrp()
