"""The sans-I/O session against a scripted board: every timer and rule, on explicit time."""

from __future__ import annotations

import pytest

from host_sdk import enums, messages
from host_sdk.errors import IncompatibleFirmwareError, NackError, RequestTimeoutError, SessionResetError
from host_sdk.framing import Frame, FrameDecoder, encode_frame
from host_sdk.profiles import PROFILES
from host_sdk.session import FailsafeEntered, LinkState, Request, ResetDetected, Session, SessionOptions
from protocol.codec.message import Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH

CONFIG = PROFILES["diffdrive-tb6612"].config
BOOT = 0x1234ABCD


class Board:
    """Scripted board side: decodes what the session sent, encodes answers."""

    def __init__(self, session: Session) -> None:
        self.session = session
        self.decoder = FrameDecoder()
        self.seq = 0

    def sent(self) -> list[tuple[Message, int]]:
        return [(e.message, e.seq) for e in self.decoder.feed(self.session.outgoing()) if isinstance(e, Frame)]

    def send(self, msg: Message, now: float) -> None:
        self.session.receive(encode_frame(msg, self.seq), now)
        self.seq = (self.seq + 1) & 0xFF

    def identity(
        self, hello_seq: int, reason: enums.IdentityReason = enums.IdentityReason.HELLO_ACCEPTED, **kw: object
    ) -> messages.Identity:
        fields: dict[str, object] = dict(
            protocol_version=PROTOCOL_VERSION,
            spec_hash=SPEC_HASH,
            firmware_version=(0, 1, 0),
            board=enums.Board.MEGA2560,
            capabilities=PROFILES["diffdrive-tb6612"].capabilities,
            boot_id=BOOT,
            uptime_ms=5,
            reason=reason,
            hello_seq=hello_seq,
            watchdog_ms=250,
            feedback_mode=enums.FeedbackMode.STREAM,
            feedback_hz=50,
            robot_name="DiffDriveTB6612",
        )
        fields.update(kw)
        return messages.Identity(**fields)  # type: ignore[arg-type]

    def feedback(
        self,
        boot_id: int = BOOT,
        status: enums.Status = enums.Status.SESSION,
        counts: tuple[int, int] = (0, 0),
        **kw: object,
    ) -> messages.Feedback:
        fields: dict[str, object] = dict(
            boot_id=boot_id,
            mcu_time_us=1000,
            tick=1,
            ack_seq=0,
            ack_tick=0,
            status=status,
            failsafe_reason=enums.FailsafeReason.NONE,
            encoder_counts=counts,
            wheel_speed_mm_s=(0, 0),
            effort_permille=(0, 0),
            steering_mrad=0,
        )
        fields.update(kw)
        return messages.Feedback(**fields)  # type: ignore[arg-type]

    def open(self, now: float = 0.0) -> None:
        """Answer the first HELLO and its GET_CONFIG."""
        sent = self.sent()
        hello = next(seq for m, seq in sent if isinstance(m, messages.Hello))
        get = next(seq for m, seq in sent if isinstance(m, messages.GetConfig))
        self.send(self.identity(hello), now)
        self.send(messages.Config(req_seq=get, **CONFIG.fields()), now)


def opened(**options: object) -> tuple[Session, Board]:
    session = Session(SessionOptions(**options))  # type: ignore[arg-type]
    board = Board(session)
    session.start(0.0)
    board.open(0.005)
    assert session.ready
    board.sent()
    return session, board


def test_hello_repeats_every_interval_with_a_get_config_behind_it_until_answered() -> None:
    session = Session(SessionOptions())
    board = Board(session)
    session.start(0.0)
    times = []
    for k in range(0, 46):
        now = k * 0.01
        session.poll(now)
        for msg, _ in board.sent():
            if isinstance(msg, messages.Hello):
                times.append(round(now, 3))
                assert msg.spec_hash == SPEC_HASH and msg.watchdog_ms == 250
    assert times == [0.0, 0.1, 0.2, 0.3, 0.4]
    session.start(0.5)
    board.open(0.51)
    assert session.state is LinkState.OPEN and session.ready and session.config == CONFIG
    for k in range(52, 100):
        session.poll(k * 0.01)
    assert not [m for m, _ in board.sent() if isinstance(m, messages.Hello)]


def test_boot_announcement_is_answered_at_once() -> None:
    session = Session(SessionOptions())
    board = Board(session)
    session.start(0.0)
    board.sent()
    board.send(board.identity(0, enums.IdentityReason.BOOT), 0.042)
    assert [type(m).__name__ for m, _ in board.sent()] == ["Hello", "GetConfig"]


def test_incompatible_spec_hash_fails_closed_naming_both_hashes() -> None:
    session = Session(SessionOptions(url="/dev/ttyACM0"))
    board = Board(session)
    session.start(0.0)
    hello = board.sent()[0][1]
    board.send(board.identity(hello, enums.IdentityReason.HELLO_REJECTED, spec_hash=0xDEADBEEF), 0.01)
    assert session.state is LinkState.INCOMPATIBLE
    err = session.error
    assert isinstance(err, IncompatibleFirmwareError)
    text = str(err)
    assert "0xDEADBEEF" in text and f"0x{SPEC_HASH:08X}" in text
    assert "roverlink firmware flash --example DiffDriveTB6612 --port /dev/ttyACM0" in text
    session.poll(1.0)
    assert board.sent() == []


def test_reliable_request_is_retried_with_the_same_seq_then_times_out() -> None:
    session, board = opened(request_timeout_s=0.1, request_tries=3)
    req = session.submit(messages.GetPid(wheel=0), 1.0)
    seqs = []
    for k in range(0, 40):
        board.send(board.feedback(), 1.0 + k * 0.01)  # the board talks: it only ignores the request
        session.poll(1.0 + k * 0.01)
        seqs += [seq for m, seq in board.sent() if isinstance(m, messages.GetPid)]
    assert len(seqs) == 3 and len(set(seqs)) == 1
    assert req.done and isinstance(req.error, RequestTimeoutError)
    assert session.stats(2.0).retries == 2 and session.stats(2.0).request_timeouts == 1


def _silent_after_request(session: Session, board: Board, until: float) -> Request:
    """The board talks until 1.0, a request goes out at 1.0, then the board says nothing until `until`."""
    board.send(board.feedback(), 1.0)
    req = session.submit(messages.GetPid(wheel=0), 1.0)
    t = 1.0
    while t < until and not req.done:
        t = round(t + 0.01, 3)
        session.poll(t)
    board.sent()
    return req


def test_a_request_meeting_a_silence_younger_than_a_bootloader_waits_for_it_to_end() -> None:
    session, board = opened(request_timeout_s=0.1, request_tries=3)
    req = _silent_after_request(session, board, 2.0)
    assert not req.done  # its tries are spent (0.3 s), but a reset may still announce itself
    t = 2.0
    while not req.done:
        t = round(t + 0.01, 3)
        session.poll(t)
    assert isinstance(req.error, RequestTimeoutError) and t == pytest.approx(1.0 + 2.0, abs=0.011)


def test_a_reset_during_that_silence_fails_the_request_with_the_reset_alone() -> None:
    session, board = opened(request_timeout_s=0.1, request_tries=3)
    req = _silent_after_request(session, board, 2.5)
    board.send(board.identity(0, reason=enums.IdentityReason.BOOT, boot_id=0x0BADF00D), 2.5)
    assert isinstance(req.error, SessionResetError) and session.stats(2.5).request_timeouts == 0


def test_a_new_request_never_reuses_the_last_requests_msg_id_and_seq() -> None:
    """The firmware would answer it as a duplicate and not apply it."""
    session, board = opened()
    req = session.submit(messages.SetPid(wheel=0, kp=1, ki=1, kd=0, kf=1, ks=0), 1.0)
    first = next(seq for m, seq in board.sent() if isinstance(m, messages.SetPid))
    board.send(messages.Ack(messages.SetPid.MSG_ID, first), 1.01)
    assert req.done and req.error is None
    for _ in range(255):  # setpoints would normally do this; PINGs are just as good
        session._send(messages.Ping(0), 1.02)
    board.sent()
    session.submit(messages.SetPid(wheel=0, kp=2, ki=1, kd=0, kf=1, ks=0), 1.03)
    sent = board.sent()
    second = next(seq for m, seq in sent if isinstance(m, messages.SetPid))
    assert second != first
    assert isinstance(sent[0][0], messages.Ping)


def test_out_of_range_nack_names_the_field() -> None:
    session, board = opened()
    req = session.submit(messages.SetConfig(**CONFIG.fields()), 1.0)
    seq = board.sent()[0][1]
    board.send(messages.Nack(messages.SetConfig.MSG_ID, seq, enums.NackReason.INVALID_CONFIG, 11), 1.01)
    assert isinstance(req.error, NackError)
    assert req.error.field == "steering_min_cdeg" and "steering_min_cdeg" in str(req.error)


def test_nack_for_a_value_the_board_does_not_define_names_the_field_and_the_value() -> None:
    """A firmware answers a reliable request holding an undefined enum value (a host built from
    another spec, or hand-made bytes) with NACK(OUT_OF_RANGE, field index): not a timeout."""
    session, board = opened()
    req = session.submit(messages.SetConfig(**CONFIG.fields()), 1.0)
    seq = board.sent()[0][1]
    safe_state = [f.name for f in messages.SetConfig.FIELDS].index("safe_state")
    board.send(messages.Nack(messages.SetConfig.MSG_ID, seq, enums.NackReason.OUT_OF_RANGE, safe_state), 1.01)
    assert isinstance(req.error, NackError) and req.error.reason is enums.NackReason.OUT_OF_RANGE
    assert req.error.field == "safe_state"
    assert f"field safe_state); sent safe_state = {CONFIG.safe_state!r}" in str(req.error)
    assert session.stats(1.02).request_timeouts == 0


def test_new_boot_id_in_feedback_ends_the_session_and_reopens() -> None:
    session, board = opened()
    session.submit(messages.Arm(BOOT), 1.0)
    arm_seq = board.sent()[0][1]
    board.send(messages.Ack(messages.Arm.MSG_ID, arm_seq), 1.01)
    assert session.armed
    session.command(messages.SetWheelSpeeds(100, 100), 1.02)
    pending = session.submit(messages.GetPid(wheel=0), 1.02)
    board.sent()
    board.send(board.feedback(boot_id=0x0BADF00D), 1.03)
    events = session.take_events()
    assert any(isinstance(e, ResetDetected) and e.new_boot_id == 0x0BADF00D for e in events)
    assert not session.armed and not session.setpoint_live and session.state is LinkState.CONNECTING
    assert isinstance(pending.error, SessionResetError)
    assert [type(m).__name__ for m, _ in board.sent()] == ["Hello", "GetConfig"]  # at once
    err = session.take_reset()
    assert isinstance(err, SessionResetError) and err.old_boot_id == BOOT
    assert session.take_reset() is None  # told once


def test_expired_command_goes_quiet_and_the_host_predicts_the_failsafe() -> None:
    session, board = opened()
    session.submit(messages.Arm(BOOT), 1.0)
    board.send(messages.Ack(messages.Arm.MSG_ID, board.sent()[0][1]), 1.0)
    session.command(messages.SetWheelSpeeds(100, 100), 1.0)
    sent_at = []
    t = 1.0
    while t < 1.5:
        session.poll(t)
        sent_at += [(t, type(m).__name__) for m, _ in board.sent()]
        t = round(t + 0.005, 3)
    # keep-alives every watchdog/4 while the command is live (command_timeout = watchdog/2), then
    # nothing until the board must have failed safe; PINGs only after that
    live_until = 1.0 + 0.125
    assert [t for t, name in sent_at if name == "SetWheelSpeeds"] == [1.0, 1.065]  # the command, one keep-alive
    assert all(t <= live_until or (name == "Ping" and t > live_until + 0.25) for t, name in sent_at)
    assert session.failsafe is enums.FailsafeReason.COMM_TIMEOUT and not session.armed
    assert any(isinstance(e, FailsafeEntered) and e.predicted for e in session.take_events())


def test_counts_are_unwrapped_across_the_i32_wrap() -> None:
    session, board = opened()
    board.send(board.feedback(counts=(2**31 - 10, -5)), 1.0)
    board.send(board.feedback(counts=(-(2**31) + 10, 5)), 1.02)
    assert session.latest is not None
    assert session.latest.encoder_counts == (2**31 + 10, 5)


def test_feedback_without_a_session_bit_reopens() -> None:
    session, board = opened()
    board.send(board.feedback(status=enums.Status(0)), 1.0)
    assert session.state is LinkState.CONNECTING


@pytest.mark.parametrize("reason", [enums.NackReason.NO_SESSION])
def test_setpoint_answered_no_session_means_the_board_lost_us(reason: enums.NackReason) -> None:
    session, board = opened()
    session.submit(messages.Arm(BOOT), 1.0)
    board.send(messages.Ack(messages.Arm.MSG_ID, board.sent()[0][1]), 1.0)
    seq = session.command(messages.SetWheelSpeeds(100, 100), 1.0)
    board.send(messages.Nack(messages.SetWheelSpeeds.MSG_ID, seq, reason, 0), 1.01)
    assert session.state is LinkState.CONNECTING and not session.armed
