"""Every injectable fault shows in the ground truth (fault log, counters) and in its effect."""

from __future__ import annotations

import math
import re

import pytest

from emulator import Emulator, FaultSpecError, UnknownProfileError, parse_faults
from emulator.errors import EmulatorValueError
from emulator.plant.esc import EscState
from host_sdk import messages
from host_sdk.enums import FailsafeReason, NackReason, Status
from host_sdk.framing import FrameErrorKind
from protocol.generated.hardware import MotorMode
from tests.support.hostlink import Host

PING_FRAME_BYTES = 10


def _armed(name: str = "diffdrive-tb6612", seed: int = 21, **kwargs: object) -> tuple[Emulator, Host]:
    emu = Emulator(name, seed=seed, **kwargs)  # type: ignore[arg-type]
    host = Host(emu)
    host.session()
    return emu, host


def test_bit_flips_host_to_mcu_cost_each_hit_frame_and_at_most_its_neighbour() -> None:
    emu, host = _armed()
    host.request(messages.Disarm())
    host.run(0.1)
    base = emu.truth.host_to_mcu.bytes_sent
    emu.set_bitflip_rate(3e-3, "h2m")
    pongs_before = len(host.of(messages.Pong))
    for i in range(200):
        host.send(messages.Ping(i))
        host.run(0.003)
    emu.set_bitflip_rate(0.0, "h2m")
    host.run(0.1)
    flips = [f for f in emu.truth.faults if f.kind == "bitflip"]
    assert flips and all(f.detail.startswith("h2m") for f in flips)
    hit = {(int(re.search(r"#(\d+)", f.detail).group(1)) - base - 1) // PING_FRAME_BYTES for f in flips}  # type: ignore[union-attr]
    pongs = len(host.of(messages.Pong)) - pongs_before
    # COBS: a flipped byte loses its frame, and at most the next one (a flipped delimiter).
    assert 200 - 2 * len(hit) <= pongs <= 200 - len(hit)
    assert emu.truth.host_to_mcu.bits_flipped == len(flips)
    stats = host.request(messages.GetLinkStats())
    assert isinstance(stats, messages.LinkStats)
    errors = stats.crc_errors + stats.cobs_errors + stats.length_errors + stats.unknown_ids + stats.value_errors
    # One error per hit frame, or two when a flip made a 0x00 that split it; a flipped delimiter
    # merges two frames into one error.
    assert len(hit) / 2 <= errors <= 2 * len(hit) and stats.crc_errors > 0
    fw = emu.truth.firmware
    assert fw is not None and fw.link.crc_errors == stats.crc_errors


def test_bit_flips_mcu_to_host_show_in_the_hosts_decoder() -> None:
    emu, host = _armed()
    emu.set_bitflip_rate(2e-3, "m2h")
    host.drive(messages.SetWheelSpeeds(200, 200), 2.0)
    truth = emu.truth
    assert truth.mcu_to_host.bits_flipped > 0 and truth.host_to_mcu.bits_flipped == 0
    assert any(bad.kind is FrameErrorKind.CRC for bad in host.bad)
    assert host.decoder.stats.crc_errors > 0
    # 2 s at 50 Hz; a 39-byte FEEDBACK survives 312 bits at 2e-3 with probability 0.53
    assert 35 < len(host.of(messages.Feedback)) < 75


def test_drops_and_insertions() -> None:
    emu, host = _armed()
    emu.set_drop_rate(0.01, "h2m")
    emu.set_insert_rate(0.01, "m2h")
    host.drive(messages.SetWheelSpeeds(200, 200), 3.0)
    emu.set_drop_rate(0.0, "h2m")
    emu.set_insert_rate(0.0, "m2h")
    truth = emu.truth
    assert truth.host_to_mcu.bytes_dropped > 0 and truth.mcu_to_host.bytes_inserted > 0
    kinds = truth.fault_kinds()
    assert kinds.count("drop") == truth.host_to_mcu.bytes_dropped
    assert kinds.count("insert") == truth.mcu_to_host.bytes_inserted
    assert host.bad  # the host saw damaged frames
    stats = host.request(messages.GetLinkStats())
    assert isinstance(stats, messages.LinkStats)
    assert stats.seq_gaps > 0  # setpoints lost on the way show as gaps in the host's seq


def test_noise_burst_damages_only_its_window() -> None:
    emu, host = _armed()
    host.drive(messages.SetWheelSpeeds(100, 100), 0.5)
    bad_before = len(host.bad)
    start = emu.now_us
    emu.noise_burst(0.1, ber=0.05)
    host.drive(messages.SetWheelSpeeds(100, 100), 0.1)
    host.run(0.01)
    bad_during = len(host.bad)
    host.drive(messages.SetWheelSpeeds(100, 100), 1.0)
    assert bad_during > bad_before and len(host.bad) <= bad_during + 1  # + a frame straddling the end
    noise = [f for f in emu.truth.faults if f.kind == "noise"]
    assert len(noise) == 2 and all(f.time_us == start for f in noise)
    assert emu.truth.mcu_to_host.noise_bytes > 0


def test_link_cut_silences_the_line_and_the_watchdog_latches_failsafe() -> None:
    emu, host = _armed()
    host.drive(messages.SetWheelSpeeds(300, 300), 1.0)
    emu.cut_link()
    cut_at = emu.now_us
    received_before = len(host.received)
    host.drive(messages.SetWheelSpeeds(300, 300), 1.0)
    assert len(host.received) == received_before  # nothing crosses a cut cable
    fw = emu.truth.firmware
    assert fw is not None and fw.state.name == "FAILSAFE" and fw.failsafe_reason is FailsafeReason.COMM_TIMEOUT
    assert emu.truth.plant.speed_m_s == 0.0
    emu.restore_link()
    host.run(0.05)
    fb = host.of(messages.Feedback)[-1]
    assert fb.status & Status.FAILSAFE and fb.failsafe_reason is FailsafeReason.COMM_TIMEOUT
    log = emu.truth.faults
    assert [(f.kind, f.time_us) for f in log if f.kind in ("cut", "restore")] == [
        ("cut", cut_at),
        ("restore", cut_at + 1_000_000),
    ]
    assert emu.truth.host_to_mcu.bytes_lost_cut > 0 and emu.truth.mcu_to_host.bytes_lost_cut > 0


def test_mcu_reset_gives_a_new_boot_and_refuses_the_old_session() -> None:
    emu, host = _armed()
    old = emu.boot_ids[-1]
    host.drive(messages.SetWheelSpeeds(300, 300), 0.5)
    emu.reset_mcu()
    assert emu.truth.mcu.phase == "bootloader" and emu.truth.firmware is None
    assert all(w.mode is MotorMode.COAST for w in emu.truth.plant.wheels)  # pins released
    boot = host.boot()
    assert boot.boot_id != old and emu.truth.mcu.resets == 1 and emu.truth.mcu.boot_ids == (old, boot.boot_id)
    # A host that missed the IDENTITY still sees it: FEEDBACK carries the new boot_id.
    host.run(0.05)
    assert host.of(messages.Feedback)[-1].boot_id == boot.boot_id
    seq = host.send(messages.SetWheelSpeeds(300, 300))  # an old-session command: refused
    assert host.wait_for(messages.Nack, 0.1, lambda m: m.req_seq == seq).reason is NackReason.NO_SESSION
    host.hello()
    answer = host.arm(old)
    assert isinstance(answer, messages.Nack) and answer.reason is NackReason.BOOT_ID_MISMATCH
    assert "reset" in emu.truth.fault_kinds() and "bootloader_garbage" in emu.truth.fault_kinds()


def test_a_reset_discards_the_uarts_backlog() -> None:
    # At 9600 baud a 100 Hz FEEDBACK stream (3900 B/s) cannot fit (960 B/s): the backlog grows.
    emu = Emulator("diffdrive-tb6612", seed=27, baud=9600, latency_us=0)
    host = Host(emu)
    host.boot()
    host.hello(hz=100)
    host.run(2.0)
    assert emu.truth.mcu_to_host.in_flight > 3000
    emu.reset_mcu()
    assert emu.truth.mcu_to_host.in_flight < 50  # only what the UART was already sending
    start = emu.now_us
    host.boot()
    # bootloader (1.5 s) + boot-counter write + the IDENTITY's 45 bytes at 9600 baud (47 ms)
    assert emu.now_us - start < 1_500_000 + 150_000


def test_brown_out_resets_the_esc_and_the_mcu() -> None:
    emu = Emulator("picar", seed=22)
    host = Host(emu)
    host.session()
    while emu.truth.plant.esc_state is not EscState.READY:
        host.send(messages.Ping(0))
        host.run(0.1)
    old = emu.boot_ids[-1]
    emu.brown_out(40)
    host.run(0.02)
    truth = emu.truth
    assert truth.mcu.phase == "reset" and truth.plant.esc_state is EscState.NO_SIGNAL
    boot = host.boot(timeout_s=0.5)
    assert boot.boot_id != old
    host.run(0.5)
    assert emu.truth.plant.esc_state is EscState.CALIBRATING  # needs its neutral again
    assert [f.kind for f in emu.truth.faults] == ["brownout"]


def test_brown_out_during_save_config_corrupts_the_record() -> None:
    emu = Emulator("diffdrive-tb6612", seed=23, eeprom="saved")
    host = Host(emu)
    host.session(arm=False)
    config = emu.profile.robot.config
    host.request(messages.SetConfig(**{**config.fields(), "feedback_hz": 25, "accel_limit_mm_s2": 1234}))
    host.send(messages.SaveConfig())
    host.run(0.008)  # the request arrived after ~1.5 ms; 3.4 ms per changed byte: 2 of 5 are programmed
    assert 0 < len(emu.pending_eeprom) < 6  # 6 bytes differ: some programmed, some not yet
    emu.brown_out(20)
    host.boot()
    host.run(0.05)
    fw = emu.truth.firmware
    assert fw is not None and fw.config_defaults and fw.config == config
    assert any(isinstance(m, messages.Log) and "EEPROM" in m.text for m in host.of(messages.Log))


def test_stalled_wheel_raises_encoder_fault_with_the_wheel_truly_stopped() -> None:
    emu, host = _armed()
    host.drive(messages.SetWheelSpeeds(300, 300), 1.0)
    emu.stall_wheel(0)
    stalled_at = emu.now_us
    host.drive(messages.SetWheelSpeeds(300, 300), 1.0)
    fb = next(f for f in host.of(messages.Feedback) if f.status & Status.FAILSAFE)
    assert fb.failsafe_reason is FailsafeReason.ENCODER_FAULT and fb.status & Status.ENCODER_FAULT
    fw = emu.truth.firmware
    assert fw is not None and fw.encoder_fault == (True, False)
    transition = next(t for t in fw.transitions if t[1].name == "FAULT")
    assert transition[0].name == "ARMED" and transition[2].name == "FAILSAFE"
    before = [f for f in host.of(messages.Feedback) if f.status & Status.ARMED][-1]
    assert before.effort_permille[0] == 1000 and before.wheel_speed_mm_s[0] == 0  # pushing, not moving
    wheel = emu.truth.plant.wheels[0]
    assert wheel.stalled and wheel.rim_speed_mm_s == 0.0 and wheel.encoder_connected
    assert ("stall", stalled_at) in [(f.kind, f.time_us) for f in emu.truth.faults]


def test_disconnected_encoder_raises_encoder_fault_while_the_wheel_turns() -> None:
    emu, host = _armed()
    host.drive(messages.SetWheelSpeeds(300, 300), 1.0)
    emu.disconnect_encoder(1)
    speeds_after = []
    for _ in range(50):
        host.send(messages.SetWheelSpeeds(300, 300))
        host.run(0.02)
        speeds_after.append(emu.truth.plant.wheels[1].rim_speed_mm_s)
        if emu.truth.status & Status.FAILSAFE:
            break
    fw = emu.truth.firmware
    assert fw is not None and fw.failsafe_reason is FailsafeReason.ENCODER_FAULT and fw.encoder_fault == (False, True)
    # Unlike a stall, the wheel really turned (faster and faster: the PID saw 0 and pushed).
    assert max(speeds_after) > 400
    wheel = emu.truth.plant.wheels[1]
    assert not wheel.encoder_connected and not wheel.stalled
    emu.reconnect_encoder(1)
    assert [f.kind for f in emu.truth.faults] == ["encoder_disconnect", "encoder_reconnect"]


def test_failing_eeprom_answers_eeprom_error() -> None:
    emu = Emulator("diffdrive-tb6612", seed=24)
    host = Host(emu)
    host.session(arm=False)
    emu.fail_eeprom()
    host.request(messages.SetPid(255, 1.5, 5.0, 0.0, 1.4, 0.0))
    answer = host.request(messages.SaveConfig(), timeout_s=1.0)
    assert isinstance(answer, messages.Nack) and answer.reason is NackReason.EEPROM_ERROR
    assert emu.truth.mcu.eeprom_failing


def test_low_traction_makes_encoder_odometry_overshoot() -> None:
    emu, host = _armed("diffdrive-bts7960")
    emu.set_traction(0.05)
    for _ in range(100):
        host.send(messages.SetWheelSpeeds(1000, 1000))
        host.run(0.01)
    truth = emu.truth
    fw = truth.firmware
    assert fw is not None
    encoder_m = fw.encoder_counts[0] / emu.profile.robot.encoder_cpr * math.pi * emu.profile.robot.wheel_diameter_m
    assert encoder_m > truth.plant.distance_m * 1.1
    assert ("traction", "mu 0.05") in [(f.kind, f.detail) for f in truth.faults]


def test_timed_fault_spec_takes_effect_on_schedule() -> None:
    spec = "cut@1.0-1.5,stall=1@2.5-2.7,encoder=0@3-3.2s,eeprom@4.5,traction=0.3,bitflip.m2h=1e-4@4-4.5,dtr@5000ms"
    emu = Emulator("diffdrive-tb6612", seed=25, faults=spec)
    emu.advance(7.0)  # the DTR reset's bootloader runs 1.5 s
    log = [(f.kind, f.time_us) for f in emu.truth.faults if f.kind not in ("bitflip", "bootloader_garbage")]
    assert log == [
        ("traction", 0),
        ("cut", 1_000_000),
        ("restore", 1_500_000),
        ("stall", 2_500_000),
        ("unstall", 2_700_000),
        ("encoder_disconnect", 3_000_000),
        ("encoder_reconnect", 3_200_000),
        ("bitflip_rate", 4_000_000),
        ("eeprom_fail", 4_500_000),  # same time: in the order the spec scheduled them
        ("bitflip_rate", 4_500_000),
        ("dtr_reset", 5_000_000),
    ]
    assert emu.truth.mcu.resets == 1 and len(emu.boot_ids) == 2


def test_reset_and_brownout_from_the_spec() -> None:
    emu = Emulator("diffdrive-tb6612", seed=26, faults="reset@1,brownout=100@3")
    emu.advance(4.0)
    assert emu.truth.mcu.resets == 2 and len(set(emu.boot_ids)) == 3 and all(emu.boot_ids)


@pytest.mark.parametrize(
    ("spec", "token", "words"),
    [
        ("bitflip=2", "bitflip=2", "probability"),
        ("cut", "cut", "needs a time"),
        ("stall=5@1", "stall=5@1", "wheel index"),
        ("wobble=1", "wobble=1", "known: bitflip"),
        ("noise@1", "noise@1", "window"),
        ("cut@3-2", "cut@3-2", "after its start"),
        ("drop.up=0.1", "drop.up=0.1", "h2m, m2h"),
        ("reset@soon", "reset@soon", "not a number"),
        ("bitflip=1e-4,reset=3@1", "reset=3@1", "takes no value"),
    ],
)
def test_bad_fault_specs_name_the_token(spec: str, token: str, words: str) -> None:
    with pytest.raises(FaultSpecError) as err:
        parse_faults(spec)
    assert err.value.token == token and words in str(err.value) and isinstance(err.value, ValueError)


def test_wheel_beyond_the_profile_is_refused() -> None:
    with pytest.raises(FaultSpecError, match=r"0\.\.0 for picar"):
        Emulator("picar", faults="stall=1@1")
    with pytest.raises(EmulatorValueError, match=r"0\.\.0 for picar"):
        Emulator("picar").stall_wheel(1)


def test_unknown_profile_lists_the_valid_names() -> None:
    with pytest.raises(UnknownProfileError) as err:
        Emulator("tank")
    assert "diffdrive-bts7960, diffdrive-tb6612, picar" in str(err.value)


def test_fault_spec_grammar() -> None:
    spec = parse_faults("bitflip=1e-4, drop.h2m=0.5 ,noise=0.1@2-2.5,brownout@1,insert.m2h=0@0")
    items = [(i.kind, i.value, i.direction, i.start_us, i.end_us) for i in spec.items]
    assert items == [
        ("bitflip", 1e-4, None, None, None),
        ("drop", 0.5, "h2m", None, None),
        ("noise", 0.1, None, 2_000_000, 2_500_000),
        ("brownout", None, None, 1_000_000, None),
        ("insert", 0.0, "m2h", 0, None),
    ]
    assert not parse_faults("") and not parse_faults(None)
