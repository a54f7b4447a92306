"""Session rules (docs/control.md 1-3, 5, 6) through the wire: what a host sees, and the ground truth."""

from __future__ import annotations

import itertools
import struct

import pytest

from emulator import Emulator
from emulator.firmware.statemachine import SessionState
from host_sdk import enums, messages
from host_sdk.enums import FailsafeReason, IdentityReason, NackReason, Status
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from protocol.generated.hardware import MotorMode
from tests.support.hostlink import Host, raw_frame


def _state(emu: Emulator) -> SessionState:
    assert emu.firmware is not None
    return emu.firmware.session.state


def test_boot_announcement_then_defaults_warning_then_idle_stream(host: Host) -> None:
    boot = host.boot()
    assert boot.reason is IdentityReason.BOOT and boot.hello_seq == 0 and boot.boot_id != 0
    assert (boot.protocol_version, boot.spec_hash) == (PROTOCOL_VERSION, SPEC_HASH)
    assert boot.board is enums.Board.EMULATOR and boot.robot_name == "DiffDriveTB6612"
    host.run(0.2)
    first = [r.message for r in host.received][:2]
    assert isinstance(first[1], messages.Log) and first[1].level is enums.LogLevel.WARN  # blank EEPROM
    feedback = host.of(messages.Feedback)
    # IDLE streams at the config's feedback_hz (50 Hz), so a host notices a reset without a session.
    assert 9 <= len(feedback) <= 11
    assert all(fb.boot_id == boot.boot_id and fb.status == Status.CONFIG_DEFAULTS for fb in feedback)


def test_saved_eeprom_boots_without_the_warning() -> None:
    host = Host(Emulator("diffdrive-tb6612", seed=1, eeprom="saved"))
    host.boot()
    host.run(0.1)
    assert not host.of(messages.Log)
    assert not host.of(messages.Feedback)[-1].status & Status.CONFIG_DEFAULTS


def test_hello_grants_are_clamped(host: Host) -> None:
    host.boot()
    ident = host.hello(watchdog_ms=10, hz=250)
    assert (ident.watchdog_ms, ident.feedback_hz) == (50, 100)
    ident = host.hello(watchdog_ms=60000, hz=0)
    assert (ident.watchdog_ms, ident.feedback_hz) == (2000, 50)  # 0: the config's default rate
    ident = host.hello(watchdog_ms=0, hz=7)
    assert (ident.watchdog_ms, ident.feedback_hz) == (250, 7)


def test_incompatible_hello_is_rejected_and_names_the_firmware_hash(host: Host) -> None:
    host.session()
    seq = host.send(messages.Hello(PROTOCOL_VERSION, SPEC_HASH ^ 1, 0, enums.FeedbackMode.STREAM, 0))
    ident = host.wait_for(messages.Identity, 0.5, lambda m: m.hello_seq == seq)
    assert ident.reason is IdentityReason.HELLO_REJECTED and ident.spec_hash == SPEC_HASH
    assert _state(host.emu) is SessionState.IDLE  # the session closed, motors safe
    answer = host.request(messages.GetConfig())
    assert isinstance(answer, messages.Nack) and answer.reason is NackReason.NO_SESSION


def test_setpoint_before_arm_is_refused_and_moves_nothing(host: Host) -> None:
    host.boot()
    seq = host.send(messages.SetWheelSpeeds(300, 300))
    nack = host.wait_for(messages.Nack, 0.2)
    assert (nack.req_seq, nack.reason) == (seq, NackReason.NO_SESSION)
    host.hello()
    for _ in range(20):
        seq = host.send(messages.SetWheelSpeeds(300, 300))
        nack = host.wait_for(messages.Nack, 0.2, lambda m, s=seq: m.req_seq == s)
        assert nack.reason is NackReason.NOT_ARMED and nack.req_id == messages.SetWheelSpeeds.MSG_ID
    truth = host.emu.truth
    assert truth.plant.distance_m == 0.0 and all(w.angle_rad == 0.0 for w in truth.plant.wheels)
    assert all(fb.effort_permille == (0, 0) for fb in host.of(messages.Feedback))


def test_arm_needs_this_boots_id(host: Host) -> None:
    ident = host.session(arm=False)
    answer = host.arm(ident.boot_id ^ 0x5A5A)
    assert isinstance(answer, messages.Nack) and answer.reason is NackReason.BOOT_ID_MISMATCH
    assert _state(host.emu) is SessionState.DISARMED
    assert isinstance(host.arm(ident.boot_id), messages.Ack)
    assert _state(host.emu) is SessionState.ARMED


def test_arm_without_session_is_no_session(host: Host) -> None:
    boot = host.boot()
    answer = host.arm(boot.boot_id)
    assert isinstance(answer, messages.Nack) and answer.reason is NackReason.NO_SESSION


def test_failsafe_in_the_first_tick_at_or_after_watchdog_expiry_and_latched(host: Host) -> None:
    emu = host.emu
    host.session(hz=100, watchdog_ms=100)  # a FEEDBACK every tick
    for _ in range(50):
        host.send(messages.SetWheelSpeeds(300, 300))
        host.run(0.01)
    assert emu.truth.plant.speed_m_s > 0.2
    fw = emu.truth.firmware
    assert fw is not None
    last_valid = fw.last_valid_frame_us  # MCU time of the last valid frame
    host.run(0.2)
    feedback = host.of(messages.Feedback)
    first = next(i for i, fb in enumerate(feedback) if fb.status & Status.FAILSAFE)
    fs, before = feedback[first], feedback[first - 1]
    assert fs.failsafe_reason is FailsafeReason.COMM_TIMEOUT and not fs.status & Status.ARMED
    assert fs.mcu_time_us - last_valid >= 100_000 > before.mcu_time_us - last_valid
    assert fs.mcu_time_us - last_valid < 100_000 + 10_000  # within one tick of expiry
    assert fs.effort_permille == (0, 0) and before.effort_permille != (0, 0)
    # The safe state is applied at the driver (diffdrive-tb6612: BRAKE) in that very tick.
    assert all(w.mode is MotorMode.BRAKE and w.duty == 0 for w in emu.truth.plant.wheels)
    # Latched: frames resume, the state stays, setpoints are refused with the reason.
    host.send(messages.Ping(1))
    host.wait_for(messages.Pong, 0.1)
    seq = host.send(messages.SetWheelSpeeds(300, 300))
    nack = host.wait_for(messages.Nack, 0.1, lambda m: m.req_seq == seq)
    assert (nack.reason, nack.detail) == (NackReason.FAILSAFE, FailsafeReason.COMM_TIMEOUT)
    host.run(0.3)
    assert _state(emu) is SessionState.FAILSAFE and emu.truth.plant.speed_m_s == 0.0
    # Only ARM (with this boot's id) clears it.
    assert isinstance(host.arm(), messages.Ack)
    fb = host.wait_for(messages.Feedback, 0.1)
    assert fb.status & Status.ARMED and fb.failsafe_reason is FailsafeReason.NONE


def test_duplicate_reliable_request_is_answered_again_but_applied_once(host: Host) -> None:
    emu = host.emu
    host.session()
    for _ in range(30):
        host.send(messages.SetWheelSpeeds(200, 200))
        host.run(0.01)
    ack = host.request(messages.ResetOdometry(), seq=100)
    assert isinstance(ack, messages.Ack) and ack.req_seq == 100
    for _ in range(20):
        host.send(messages.SetWheelSpeeds(200, 200))
        host.run(0.01)
    fw = emu.truth.firmware
    assert fw is not None
    counts, duplicates = fw.encoder_counts, fw.link.duplicates
    assert counts[0] > 100
    again = host.request(messages.ResetOdometry(), seq=100)  # a retry: same msg_id and seq
    assert again == ack
    fw = emu.truth.firmware
    assert fw is not None
    assert fw.link.duplicates == duplicates + 1
    assert fw.encoder_counts[0] >= counts[0]  # not reset again
    # Another seq is a new request.
    assert isinstance(host.request(messages.ResetOdometry(), seq=101), messages.Ack)
    fw = emu.truth.firmware
    assert fw is not None and abs(fw.encoder_counts[0]) < 20


def test_duplicate_set_pid_and_fresh_get_pid(host: Host) -> None:
    host.session(arm=False)
    first = host.request(messages.SetPid(0, 2.0, 3.0, 0.0, 1.0, 20.0), seq=40)
    assert isinstance(first, messages.Ack)
    assert host.request(messages.SetPid(0, 2.0, 3.0, 0.0, 1.0, 20.0), seq=40) == first
    fw = host.emu.truth.firmware
    assert fw is not None and fw.link.duplicates == 1
    reply = host.request(messages.GetPid(0), seq=41)
    assert isinstance(reply, messages.Pid) and (reply.kp, reply.ki, reply.kf, reply.ks) == (2.0, 3.0, 1.0, 20.0)
    # A retried GET is answered with the current values (another SET_PID in between).
    host.request(messages.SetPid(255, 4.0, 3.0, 0.0, 1.0, 0.0), seq=42)
    host.request(messages.GetPid(0), seq=43)
    again = host.request(messages.GetPid(0), seq=43)
    assert isinstance(again, messages.Pid) and again.kp == 4.0 and again.req_seq == 43


def test_set_pid_out_of_range_fields_name_their_index(host: Host) -> None:
    host.session(arm=False)
    nan = struct.pack("<Bfffff", 0, 1.0, float("nan"), 0.0, 1.0, 0.0)
    host.send_raw(raw_frame(messages.SetPid, nan, seq=60))
    nack = host.wait_for(messages.Nack, 0.2)
    assert (nack.req_seq, nack.reason, nack.detail) == (60, NackReason.OUT_OF_RANGE, 2)
    bad_wheel = host.request(messages.SetPid(7, 1.0, 1.0, 0.0, 1.0, 0.0))
    assert isinstance(bad_wheel, messages.Nack) and (bad_wheel.reason, bad_wheel.detail) == (NackReason.OUT_OF_RANGE, 0)
    fw = host.emu.truth.firmware
    assert fw is not None and fw.gains[0].ki == 6.0  # unchanged


@pytest.mark.parametrize(
    ("field", "value", "reason"),
    [
        ("watchdog_ms", 20, NackReason.OUT_OF_RANGE),
        ("max_effort_permille", 1200, NackReason.OUT_OF_RANGE),
        ("feedback_hz", 0, NackReason.OUT_OF_RANGE),
        ("servo_max_us", 450, NackReason.INVALID_CONFIG),
        ("esc_min_us", 1600, NackReason.INVALID_CONFIG),
    ],
)
def test_set_config_refused_changes_nothing(host: Host, field: str, value: int, reason: NackReason) -> None:
    host.session(arm=False)
    config = host.emu.profile.robot.config
    values = {**config.fields(), field: value}
    names = [f.name for f in messages.SetConfig.FIELDS]
    fmt = "<HBHHHHHBBIHHHHHHHHHHB"
    host.send_raw(raw_frame(messages.SetConfig, struct.pack(fmt, *values.values()), seq=77))
    nack = host.wait_for(messages.Nack, 0.2)
    assert (nack.req_id, nack.req_seq, nack.reason) == (messages.SetConfig.MSG_ID, 77, reason)
    expected = {
        "servo_max_us": names.index("servo_min_us"),
        "esc_min_us": names.index("esc_min_us"),
    }.get(field, names.index(field))
    assert nack.detail == expected
    reply = host.request(messages.GetConfig())
    assert isinstance(reply, messages.Config)
    assert {k: v for k, v in reply.fields().items() if k != "req_seq"} == config.fields()


def test_set_config_applies_and_get_config_reads_it_back(host: Host) -> None:
    host.session(arm=False)
    config = host.emu.profile.robot.config
    new = messages.SetConfig(**{**config.fields(), "max_wheel_speed_mm_s": 400})
    assert isinstance(host.request(new), messages.Ack)
    assert isinstance(host.arm(), messages.Ack)
    seq = host.send(messages.SetWheelSpeeds(450, 0))
    nack = host.wait_for(messages.Nack, 0.1)
    assert (nack.req_seq, nack.reason, nack.detail) == (seq, NackReason.OUT_OF_RANGE, 0)
    seq = host.send(messages.SetWheelSpeeds(0, -401))
    nack = host.wait_for(messages.Nack, 0.1)
    assert (nack.req_seq, nack.detail) == (seq, 1)


def test_save_config_survives_a_reset_and_is_refused_while_armed() -> None:
    emu = Emulator("diffdrive-tb6612", seed=3)
    host = Host(emu)
    host.session()
    saved = host.request(messages.SaveConfig())
    assert isinstance(saved, messages.Nack) and saved.reason is NackReason.ARMED
    host.request(messages.Disarm())
    config = emu.profile.robot.config
    host.request(messages.SetConfig(**{**config.fields(), "feedback_hz": 20}))
    host.request(messages.SetPid(1, 0.5, 2.0, 0.0, 1.75, 35.0))
    t0 = emu.now_us
    assert isinstance(host.request(messages.SaveConfig()), messages.Ack)
    assert emu.now_us - t0 > 50_000  # dozens of changed bytes at 3.4 ms each: the loop stalled
    emu.reset_mcu()
    boot = host.boot()
    host.run(0.5)
    fw = emu.truth.firmware
    assert fw is not None and not fw.config_defaults and fw.config.feedback_hz == 20
    assert fw.gains[1].kf == 1.75 and fw.gains[1].ks == 35.0 and fw.gains[0].kf == emu.profile.robot.pid.kf
    assert fw.boot_count == 2 and boot.boot_id != emu.boot_ids[0]
    idle = [fb for fb in host.of(messages.Feedback) if fb.boot_id == boot.boot_id]
    assert 9 <= len(idle) <= 11  # 20 Hz in IDLE now
    assert not any(isinstance(r.message, messages.Log) and r.time_us > emu.now_us - 500_000 for r in host.received)


def test_host_bytes_during_an_eeprom_stall_overrun_the_receive_buffer() -> None:
    emu = Emulator("diffdrive-tb6612", seed=3)
    host = Host(emu)
    host.session(arm=False)
    host.send(messages.SaveConfig())
    host.run(0.002)  # the request has arrived; the loop is programming EEPROM
    for i in range(20):
        host.send(messages.Ping(i))  # 200 bytes while the buffer holds 63
    host.run(0.5)
    truth = emu.truth
    assert truth.mcu.rx_overrun_bytes > 100 and "rx_overrun" in truth.fault_kinds()
    assert len(host.of(messages.Pong)) < 20
    # The stall also made the loop skip control ticks (kept on their grid, not replayed).
    assert truth.mcu.ticks_skipped > 5
    # The Arduino core drops overruns silently: the firmware cannot report them. (The first try is
    # lost: the overrun cut a PING short, and its head swallows the next frame. A host retries.)
    seq = host.send(messages.GetLinkStats())
    host.run(0.1)
    assert not host.of(messages.LinkStats)
    stats = host.request(messages.GetLinkStats(), seq=seq)
    assert isinstance(stats, messages.LinkStats) and stats.rx_overruns == 0
    assert stats.cobs_errors + stats.crc_errors + stats.length_errors == 1


def test_lockstep_one_feedback_per_applied_setpoint() -> None:
    emu = Emulator("diffdrive-bts7960", seed=2)
    host = Host(emu)
    ident = host.session(mode=enums.FeedbackMode.LOCKSTEP)
    assert ident.feedback_mode is enums.FeedbackMode.LOCKSTEP
    host.run(0.02)  # (IDLE streamed at 100 Hz until the HELLO; the session does not)
    before = len(host.of(messages.Feedback))
    host.run(0.2)
    assert len(host.of(messages.Feedback)) == before  # nothing unsolicited in lockstep
    for _ in range(30):
        seq = host.send(messages.SetWheelSpeeds(400, 400))
        fb = host.wait_for(messages.Feedback, 0.05)
        assert fb.ack_seq == seq and fb.status & Status.LOCKSTEP and fb.tick == fb.ack_tick
    # Three setpoints inside one tick: the queue (LOCKSTEP_QUEUE, 2) takes two, the third
    # supersedes the second; the first and third are answered, in two consecutive ticks.
    host.run(0.004)
    first, second, third = (host.send(messages.SetWheelSpeeds(v, v)) for v in (100, 200, 300))
    done = len(host.of(messages.Feedback))
    host.run(0.05)
    answers = host.of(messages.Feedback)[done:]
    assert [fb.ack_seq for fb in answers] == [first, third], (second, answers)
    assert answers[1].tick - answers[0].tick == 1


def test_lockstep_streams_while_not_armed_from_the_first_tick_out_of_armed() -> None:
    host = Host(Emulator("diffdrive-bts7960", seed=3))
    host.session(mode=enums.FeedbackMode.LOCKSTEP, hz=20, arm=False)
    start = len(host.of(messages.Feedback))
    host.run(1.0)
    disarmed = host.of(messages.Feedback)[start:]
    assert len(disarmed) >= 20 and {b.tick - a.tick for a, b in itertools.pairwise(disarmed)} == {5}
    assert all(fb.status & Status.LOCKSTEP and not fb.status & Status.ARMED for fb in disarmed)
    assert isinstance(host.request(messages.Arm(disarmed[0].boot_id)), messages.Ack)
    seq = host.send(messages.SetWheelSpeeds(0, 0))
    answer = host.wait_for(messages.Feedback, 0.05)
    assert answer.ack_seq == seq and answer.status & Status.ARMED
    start = len(host.of(messages.Feedback))
    host.run(0.1)  # armed, no setpoint, within the watchdog: silent
    assert len(host.of(messages.Feedback)) == start
    assert isinstance(host.request(messages.Disarm()), messages.Ack)
    host.run(0.015)  # the first tick out of ARMED streams one (the period is 50 ms)
    assert len(host.of(messages.Feedback)) == start + 1
    host.run(0.5)
    after = host.of(messages.Feedback)[start:]
    assert len(after) >= 10 and {b.tick - a.tick for a, b in itertools.pairwise(after)} == {5}
    assert not any(fb.status & Status.ARMED for fb in after)


@pytest.mark.parametrize(("hz", "expected"), [(50, 100), (100, 200), (30, 67), (7, 14)])
def test_stream_rate_follows_feedback_hz(hz: int, expected: int) -> None:
    host = Host(Emulator("diffdrive-tb6612", seed=4))
    host.session(hz=hz, arm=False)
    host.received.clear()
    host.run(2.0)
    # round(100 / hz) ticks apart: 30 Hz -> every 3 ticks (33.3 Hz), 7 Hz -> every 14 ticks (7.1 Hz)
    assert abs(len(host.of(messages.Feedback)) - expected) <= 1
    ticks = [fb.tick for fb in host.of(messages.Feedback)]
    assert {b - a for a, b in itertools.pairwise(ticks)} == {round(100 / hz)}


def test_ping_pong_and_crystal_drift() -> None:
    emu = Emulator("diffdrive-tb6612", seed=5, drift_ppm=150)
    host = Host(emu)
    host.boot()
    host.run(0.1)  # let the boot IDENTITY and LOG leave the line: a PONG would queue behind them
    pongs = []
    for i in range(5):
        sent = emu.now_us
        host.send(messages.Ping(0xDEAD0000 + i))
        pongs.append((sent, host.wait_for(messages.Pong, 0.1)))
        host.run(1.0)
    assert [p.host_time_us for _, p in pongs] == [0xDEAD0000 + i for i in range(5)]
    (t0, p0), (t1, p1) = pongs[0], pongs[-1]
    rate = (p1.mcu_time_us - p0.mcu_time_us) / (t1 - t0)
    assert rate == pytest.approx(1 + 150e-6, abs=3e-6)
    assert all(p.mcu_time_us % 4 == 0 for _, p in pongs)  # micros() has 4 us steps on a 16 MHz AVR


def test_unsupported_setpoint_kinds() -> None:
    host = Host(Emulator("diffdrive-tb6612", seed=1))
    host.session()
    host.send(messages.SetAckermann(100, 0))
    assert host.wait_for(messages.Nack, 0.1).reason is NackReason.UNSUPPORTED
    car = Host(Emulator("picar", seed=1))
    car.session()
    car.send(messages.SetWheelSpeeds(100, 100))
    assert car.wait_for(messages.Nack, 0.1).reason is NackReason.UNSUPPORTED


def test_link_stats_count_bad_frames_and_seq_gaps(host: Host) -> None:
    host.session(arm=False)
    host.send(messages.Ping(4))  # the first frame after HELLO only sets last_seq (1.2.1)
    frame = bytearray(raw_frame(messages.Ping, struct.pack("<I", 5), seq=host.seq))
    frame[3] ^= 0x01
    host.send_raw(bytes(frame))  # a CRC error
    host.seq = (host.seq + 5) & 0xFF  # the corrupted frame and four more never arrive
    stats = host.request(messages.GetLinkStats())
    assert isinstance(stats, messages.LinkStats)
    assert stats.crc_errors == 1 and stats.seq_gaps == 5  # the corrupted one and the 4 skipped
    assert stats.frames_ok >= 3 and stats.frames_sent > 5
    assert stats.bytes_discarded == len(frame) - 1


def test_disarm_with_ramp_down_safe_state_decelerates_then_coasts() -> None:
    emu = Emulator("diffdrive-bts7960", seed=6)
    host = Host(emu)
    host.session()
    for _ in range(150):
        host.send(messages.SetWheelSpeeds(800, 800))
        host.run(0.01)
    assert isinstance(host.request(messages.Disarm()), messages.Ack)
    decel = emu.profile.robot.config.decel_limit_mm_s2
    ramped = []
    for _ in range(40):
        host.run(0.01)
        fw = emu.truth.firmware
        assert fw is not None
        ramped.append(fw.ramped_mm_s[0])
    steps = [a - b for a, b in itertools.pairwise(ramped) if a > 0]
    assert steps and max(steps) == pytest.approx(decel / 100)  # ramped down at the decel limit
    assert ramped[-1] == 0.0
    assert all(w.mode is MotorMode.COAST for w in emu.truth.plant.wheels)
    assert _state(emu) is SessionState.DISARMED


def test_esc_drive_held_at_neutral_during_the_arming_window() -> None:
    emu = Emulator("picar", seed=7)
    host = Host(emu)
    host.session()
    for _ in range(100):
        host.send(messages.SetAckermann(800, 0))
        host.run(0.01)
    truth = emu.truth
    assert truth.firmware is not None and truth.firmware.esc_hold
    assert truth.plant.esc_pulse_us == 1500 and truth.plant.distance_m == 0.0
    host.run(0.0)
    while emu.now_us < 3_400_000:
        host.send(messages.SetAckermann(800, 0))
        host.run(0.01)
    truth = emu.truth
    assert truth.plant.esc_state is not None and truth.plant.esc_state.name == "READY"
    assert truth.plant.esc_neutral_us == 1500 and truth.plant.speed_m_s > 0.2


def test_lockstep_is_granted_only_with_the_capability() -> None:
    car = Host(Emulator("picar", seed=8))  # no LOCKSTEP capability
    car.boot()
    assert car.hello(mode=enums.FeedbackMode.LOCKSTEP).feedback_mode is enums.FeedbackMode.STREAM
    slam = Host(Emulator("diffdrive-bts7960", seed=8))
    slam.boot()
    assert slam.hello(mode=enums.FeedbackMode.LOCKSTEP).feedback_mode is enums.FeedbackMode.LOCKSTEP
