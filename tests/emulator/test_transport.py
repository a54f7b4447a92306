"""Transports: the in-memory serial port on the virtual clock, and the real-time pty and socket
served by `roverlink emulate` in a subprocess, opened with pyserial."""

from __future__ import annotations

import signal
import subprocess
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import serial

from emulator import Emulator
from emulator.transport import MemorySerial
from emulator.transport.memory import PortClosedError
from host_sdk import enums, messages
from host_sdk.framing import Frame, FrameDecoder, encode_frame
from protocol.codec.message import Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from roverlink.cli import main as roverlink_main
from tests.support.emulate import EmulatorProcess
from tests.support.wait import Deadline

HELLO = messages.Hello(PROTOCOL_VERSION, SPEC_HASH, 0, enums.FeedbackMode.STREAM, 0)


# == in memory =========================================================================================
def test_memory_serial_reads_wait_in_virtual_time() -> None:
    emu = Emulator("diffdrive-tb6612", seed=31)
    emu.advance(0.5)
    port = MemorySerial(emu, timeout=3.0)  # opening resets the board, as DTR does
    assert emu.truth.mcu.phase == "bootloader"
    t0 = emu.now_us
    data = port.read_until(b"\x00")  # the bootloader's garbage, ended by the UART's start-up break
    data += port.read_until(b"\x00")  # then the boot IDENTITY
    assert 1.5e6 <= emu.now_us - t0 < 1.6e6  # waited out the Mega's bootloader, in virtual time
    events = FrameDecoder().feed(data)
    frames = [e for e in events if isinstance(e, Frame)]
    assert isinstance(frames[0].message, messages.Identity) and frames[0].message.reason is enums.IdentityReason.BOOT
    assert frames[0].message.boot_id == emu.boot_ids[-1] != emu.boot_ids[0]
    port.write(encode_frame(HELLO, 0))
    reply = port.read_until(b"\x00")
    while not any(
        isinstance(e, Frame) and isinstance(e.message, messages.Identity) for e in FrameDecoder().feed(reply)
    ):
        reply = port.read_until(b"\x00")
    port.timeout = 0.05
    t0 = emu.now_us
    assert len(port.read(100_000)) < 100_000 and emu.now_us - t0 == 50_000  # a timeout, exactly
    port.timeout = 0
    t0 = emu.now_us
    port.read(10_000)
    assert emu.now_us == t0  # non-blocking: no time passes


def test_memory_serial_dtr_edge_resets_and_closed_port_refuses() -> None:
    emu = Emulator("picar", seed=32)
    port = MemorySerial(emu, timeout=0.1, dtr_reset_on_open=False)
    emu.advance(1.0)
    assert emu.truth.mcu.resets == 0
    port.dtr = False
    port.dtr = True  # the auto-reset capacitor passes the rising edge to RESET
    assert emu.truth.mcu.resets == 1 and emu.truth.mcu.phase == "bootloader"
    port.close()
    with pytest.raises(PortClosedError):
        port.write(b"\x00")
    with pytest.raises(OSError):
        port.read(1)


# == real time, in a subprocess ==========================================================================
@pytest.fixture
def emulate() -> Iterator[Callable[..., tuple[subprocess.Popen[str], str]]]:
    served: list[EmulatorProcess] = []

    def start(*args: str) -> tuple[subprocess.Popen[str], str]:
        served.append(EmulatorProcess(*args, stderr=subprocess.PIPE))
        return served[-1].proc, served[-1].url

    yield start
    for board in served:
        board.stop()


class _Reader:
    """Frames from a pyserial port, with deadlines instead of sleeps."""

    def __init__(self, port: Any) -> None:
        self.port = port
        self.decoder = FrameDecoder()
        self.raw = bytearray()

    def wait_for(self, pred: Callable[[Message], bool], timeout_s: float) -> Message:
        deadline = Deadline(timeout_s)
        while not deadline.expired():
            data = self.port.read(512)
            self.raw += data
            for event in self.decoder.feed(data):
                if isinstance(event, Frame) and pred(event.message):
                    return event.message
        raise AssertionError(f"no matching frame within {timeout_s} s; got {len(self.raw)} bytes")


def _boot_identity(m: Message) -> bool:
    return isinstance(m, messages.Identity) and m.reason is enums.IdentityReason.BOOT


def test_pty_open_resets_the_board_and_serves_the_protocol(emulate: Callable[..., tuple[Any, str]]) -> None:
    proc, path = emulate("--profile", "diffdrive-tb6612", "--seed", "5")
    assert path.startswith("/dev/")
    port = serial.Serial(path, 115200, timeout=0.05)
    reader = _Reader(port)
    boot = reader.wait_for(_boot_identity, 10.0)
    assert isinstance(boot, messages.Identity)
    # Garbage from the bootloader came first and was discarded by the decoder, not mistaken for a frame.
    assert reader.decoder.stats.bytes_discarded >= 1 and reader.raw.index(b"\x00") >= 1
    port.write(encode_frame(HELLO, 0))
    ident = reader.wait_for(lambda m: isinstance(m, messages.Identity) and m.hello_seq == 0 and m.reason != 0, 2.0)
    assert isinstance(ident, messages.Identity) and ident.reason is enums.IdentityReason.HELLO_ACCEPTED
    port.write(encode_frame(messages.Arm(boot.boot_id), 1))
    ack = reader.wait_for(lambda m: isinstance(m, (messages.Ack, messages.Nack)), 2.0)
    assert ack == messages.Ack(messages.Arm.MSG_ID, 1)
    for seq in range(2, 40):
        port.write(encode_frame(messages.SetWheelSpeeds(200, 200), seq))
        fb = reader.wait_for(lambda m: isinstance(m, messages.Feedback), 2.0)
    assert isinstance(fb, messages.Feedback) and fb.status & enums.Status.ARMED and fb.boot_id == boot.boot_id
    assert fb.encoder_counts[0] > 0
    port.close()
    # Reopening is a DTR reset: a new boot with a new boot_id.
    port = serial.Serial(path, 115200, timeout=0.05)
    again = _Reader(port).wait_for(_boot_identity, 10.0)
    assert isinstance(again, messages.Identity) and again.boot_id != boot.boot_id
    port.close()
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=10)
    assert proc.returncode == 0 and "Traceback" not in err
    assert err.count("DTR reset") == 2


def test_socket_endpoint_with_pyserial_url(emulate: Callable[..., tuple[Any, str]]) -> None:
    proc, url = emulate("--profile", "picar", "--socket", "0", "--bootloader-ms", "200", "--quiet")
    assert url.startswith("socket://127.0.0.1:")
    port = serial.serial_for_url(url, timeout=0.05)
    reader = _Reader(port)
    boot = reader.wait_for(_boot_identity, 10.0)
    assert isinstance(boot, messages.Identity) and boot.robot_name == "AckermannPiCar"
    port.write(encode_frame(messages.Ping(1234), 0))
    pong = reader.wait_for(lambda m: isinstance(m, messages.Pong), 2.0)
    assert isinstance(pong, messages.Pong) and pong.host_time_us == 1234
    port.close()
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=10)
    assert proc.returncode == 0 and err == ""


def test_cli_errors_name_the_bad_value(capsys: pytest.CaptureFixture[str]) -> None:
    assert roverlink_main(["emulate", "--faults", "cut@2,wobble=1"]) == 2
    err = capsys.readouterr().err
    assert "wobble=1" in err and "known: bitflip" in err
    with pytest.raises(SystemExit) as exit_info:
        roverlink_main(["emulate", "--profile", "tank"])
    assert exit_info.value.code == 2
    assert "diffdrive-tb6612" in capsys.readouterr().err


def test_roverlink_emulate_is_registered() -> None:
    from roverlink.cli import main

    with pytest.raises(SystemExit) as exit_info:
        main(["emulate", "--help"])
    assert exit_info.value.code == 0
