"""The firmware core (arduino/RoverLink/src/core), built natively, against docs/control.md.

Two layers:

* ``make -C tests/firmware/native core-test``: the C++ unit tests (PID, ramp, pulses, session, watchdog,
  EEPROM, lockstep, link statistics...), plain and under AddressSanitizer + UBSan, and
  ``make core-avr``: every core .cpp compiled with avr-g++ against the Arduino core.
* The same core as a shared library (``native_sim.py``, ctypes) driven from Python with the SDK's
  codec (``host_sdk.framing``): handshake, arming, a simulated motor closing the PID loop, watchdog
  timing, lockstep, resets, the EEPROM, and Hypothesis streams of garbage and valid frames.
"""

from __future__ import annotations

import dataclasses
import math
import re
import shutil
import subprocess
from dataclasses import dataclass, field

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from host_sdk import messages
from host_sdk.framing import Frame
from host_sdk.testing import strategies as rls
from protocol.codec.message import Direction
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH, WATCHDOG_MIN_MS
from protocol.generated.enums import (
    Capability,
    FailsafeReason,
    FeedbackMode,
    IdentityReason,
    LogLevel,
    NackReason,
    Status,
)
from protocol.generated.hardware import MotorMode
from protocol.generated.profiles import PROFILES
from protocol.generated.state_machine import SessionState
from tests.support import make, native_sim
from tests.support.hostlink import Received, hello
from tests.support.native_sim import HostLink, NativeSim

PROFILE_NAMES = sorted(PROFILES)
TICK_US = 10_000


def _make(*targets: str) -> subprocess.CompletedProcess[str]:
    return make.require_make(native_sim.NATIVE_DIR, *targets, build=native_sim.BUILD_DIR)


@pytest.fixture(scope="module", autouse=True)
def _library() -> None:
    try:
        native_sim.library()
    except native_sim.SimError as exc:
        pytest.fail(str(exc), pytrace=False)


def only(frames: list[Received], cls: type) -> list:  # type: ignore[type-arg]
    return [f.message for f in frames if isinstance(f.message, cls)]


def open_and_arm(sim: NativeSim, host: HostLink, **kw: int) -> None:
    host.send(hello(**kw))  # type: ignore[arg-type]
    host.send(messages.Arm(boot_id=sim.outputs().boot_id))
    host.run()
    assert sim.outputs().state == SessionState.ARMED


# -- a plant: first-order DC motor + wheel + encoder, in the Board's raw terms ---------------------
@dataclass
class Motor:
    counts_per_mm: float
    gain_mm_s: float = 700.0  # steady speed at full effort
    tau_s: float = 0.08
    speed_mm_s: float = 0.0
    position: float = 0.0

    def step(self, effort_permille: float, dt: float) -> None:
        self.speed_mm_s += (self.gain_mm_s * effort_permille / 1000.0 - self.speed_mm_s) * dt / self.tau_s
        self.position += self.speed_mm_s * dt * self.counts_per_mm


@dataclass
class Plant:
    sim: NativeSim
    profile: str
    motors: list[Motor] = field(default_factory=list)
    trace: list[float] = field(default_factory=list)  # wheel 0's true speed, every ms

    def __post_init__(self) -> None:
        cfg = PROFILES[self.profile].config
        cpm = cfg.encoder_cpr / (math.pi * cfg.wheel_diameter_um / 1000.0)
        n = 2 if Capability.DIFF_DRIVE in PROFILES[self.profile].capabilities else 1
        # The motor the example's gains were tuned for: its feed-forward alone reaches the target.
        gain = 1000.0 / PROFILES[self.profile].pid.kf
        self.motors = [Motor(counts_per_mm=cpm, gain_mm_s=gain) for _ in range(n)]

    def effort(self, wheel: int) -> float:
        out = self.sim.outputs()
        if wheel == 0 and Capability.ESC in PROFILES[self.profile].capabilities:
            cfg = PROFILES[self.profile].config
            if out.esc_us == 0:
                return 0.0
            if out.esc_us >= cfg.esc_neutral_us:
                return 1000.0 * (out.esc_us - cfg.esc_neutral_us) / (cfg.esc_max_us - cfg.esc_neutral_us)
            return 1000.0 * (out.esc_us - cfg.esc_neutral_us) / (cfg.esc_neutral_us - cfg.esc_min_us)
        return float(out.motor_effort[wheel]) if out.motor_mode[wheel] == MotorMode.DRIVE else 0.0

    def run(self, host: HostLink, ms: int, keepalive: messages.Message | None = None) -> list[Received]:
        for t in range(ms):
            if keepalive is not None and t % 50 == 0:
                host.send(keepalive)
            for w, motor in enumerate(self.motors):
                motor.step(self.effort(w), 0.001)
                self.sim.set_encoder(w, math.floor(motor.position))
            self.sim.advance_us(1000)
            self.trace.append(self.motors[0].speed_mm_s)
        return host.receive()


# -- the C++ side ----------------------------------------------------------------------------------
def test_core_unit_tests_pass() -> None:
    out = _make("core-test").stdout
    results = re.findall(r"^(\d+) passed, (\d+) failed$", out, re.M)
    assert len(results) == 2, out  # plain and sanitizers
    assert all(int(passed) > 1000 and failed == "0" for passed, failed in results), out


def test_core_builds_for_avr() -> None:
    if shutil.which("avr-g++") is None:
        pytest.fail("avr-g++ is required (scripts/test.sh installs gcc-avr and avr-libc)", pytrace=False)
    out = _make("core-avr").stdout
    assert "SKIPPED" not in out, out
    sizes = {m[0]: int(m[1]) for m in re.findall(r"^sizeof_(\w+) on atmega328p: (\d+) bytes$", out, re.M)}
    assert set(sizes) >= {"Link", "Session", "Firmware", "FrameDecoder"}, out
    # The session's state (link buffers included) in the design's SRAM budget for link + session
    # (docs/budgets.md: <= 400 B); all of the core's (session, control, config, the lockstep
    # queue) held near its 406 B (docs/firmware.md), well within half the Uno's SRAM.
    assert sizes["Session"] <= 400 and sizes["Session"] <= sizes["Firmware"] <= 416, sizes


def test_library_knows_every_profile() -> None:
    assert native_sim.profiles() == {name: p.example for name, p in PROFILES.items()}


# -- boot and handshake -----------------------------------------------------------------------------
@pytest.mark.parametrize("name", PROFILE_NAMES)
def test_boot_announcement_then_handshake(name: str) -> None:
    profile = PROFILES[name]
    with NativeSim(name, seed=3) as sim:
        host = HostLink(sim)
        frames = host.run()
        boot = frames[0].message
        assert isinstance(boot, messages.Identity)
        assert frames[0].seq == 0
        assert boot.reason == IdentityReason.BOOT
        assert (boot.protocol_version, boot.spec_hash) == (PROTOCOL_VERSION, SPEC_HASH)
        assert boot.board == profile.board
        assert boot.capabilities == profile.capabilities
        assert boot.robot_name == profile.example
        assert boot.boot_id == sim.outputs().boot_id != 0
        log = frames[1].message  # a blank EEPROM: defaults, and it says so
        assert isinstance(log, messages.Log) and log.level == LogLevel.WARN and "defaults" in log.text

        seq = host.send(hello(profile.feedback_mode, 0, 300))
        (reply,) = host.run()
        assert isinstance(reply.message, messages.Identity)
        assert reply.message.reason == IdentityReason.HELLO_ACCEPTED
        assert reply.message.hello_seq == seq
        assert reply.message.watchdog_ms == 300
        assert reply.message.feedback_mode == profile.feedback_mode
        assert reply.message.feedback_hz == profile.config.feedback_hz
        assert reply.message.boot_id == boot.boot_id
        assert sim.outputs().state == SessionState.DISARMED


def test_spec_hash_mismatch_is_refused_and_never_arms() -> None:
    with NativeSim("diffdrive-tb6612") as sim:
        host = HostLink(sim)
        host.run()
        bad = messages.Hello(PROTOCOL_VERSION, SPEC_HASH ^ 0xFFFF, 0, FeedbackMode.STREAM, 0)
        host.send(bad)
        host.send(messages.Arm(boot_id=sim.outputs().boot_id))
        frames = host.run(200_000)
        (ident,) = only(frames, messages.Identity)
        assert ident.reason == IdentityReason.HELLO_REJECTED
        assert ident.spec_hash == SPEC_HASH  # the firmware's own: the host can name both hashes
        (nack,) = only(frames, messages.Nack)
        assert nack.reason == NackReason.NO_SESSION
        assert sim.outputs().state == SessionState.IDLE
        assert all(not (fb.status & Status.ARMED) for fb in only(frames, messages.Feedback))


def test_setpoints_before_arm_are_refused() -> None:
    with NativeSim("diffdrive-tb6612") as sim:
        host = HostLink(sim)
        host.send(hello())
        seq = host.send(messages.SetWheelSpeeds(200, 200))
        frames = host.run(50_000)
        nacks = [n for n in only(frames, messages.Nack) if n.req_seq == seq]
        assert [n.reason for n in nacks] == [NackReason.NOT_ARMED]
        assert sim.outputs().motor_mode == (MotorMode.BRAKE, MotorMode.BRAKE)


# -- control ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", PROFILE_NAMES)
def test_pid_converges_on_a_simulated_motor(name: str) -> None:
    profile = PROFILES[name]
    target = 400
    with NativeSim(name, seed=5) as sim:
        host = HostLink(sim)
        open_and_arm(sim, host, mode=profile.feedback_mode, watchdog_ms=1000)
        plant = Plant(sim, name)
        if Capability.ACKERMANN in profile.capabilities:
            go: messages.Message = messages.SetAckermann(speed_mm_s=target, steering_mrad=0)
        else:
            go = messages.SetWheelSpeeds(left_mm_s=target, right_mm_s=target)
        plant.run(host, profile.config.esc_arm_ms + 3000, go)
        tail = plant.trace[-500:]
        mean = sum(tail) / len(tail)
        assert abs(mean - target) < 0.03 * target, (name, mean)
        assert max(tail) - min(tail) < 0.06 * target, (name, min(tail), max(tail))  # no sustained oscillation
        out = sim.outputs()
        assert out.state == SessionState.ARMED
        assert all(abs(m - target) < 0.1 * target for m in out.measured_mm_s[: len(plant.motors)])
        fbs = only(host.received, messages.Feedback)
        assert fbs and abs(fbs[-1].wheel_speed_mm_s[0] - target) < 0.1 * target


def test_failsafe_comes_within_one_tick_of_the_watchdog() -> None:
    for phase_us in (0, 2_500, 7_300, 9_900):
        with NativeSim("diffdrive-tb6612") as sim:
            sim.poll_interval_us = 100
            host = HostLink(sim)
            sim.advance_us(20_000 + phase_us)
            open_and_arm(sim, host, watchdog_ms=WATCHDOG_MIN_MS)
            last_frame = sim.time_us
            expiry = last_frame + WATCHDOG_MIN_MS * 1000
            while sim.outputs().state == SessionState.ARMED:
                sim.advance_us(100)
            failed_at = sim.time_us
            assert expiry <= failed_at < expiry + TICK_US, (phase_us, failed_at - expiry)
            out = sim.outputs()
            assert out.failsafe_reason == FailsafeReason.COMM_TIMEOUT
            assert out.motor_mode == (MotorMode.BRAKE, MotorMode.BRAKE)
            # Latched: frames do not clear it, setpoints are refused with the reason, ARM does.
            host.send(messages.Ping(host_time_us=1))
            seq = host.send(messages.SetWheelSpeeds(100, 100))
            frames = host.run(100_000)
            nack = next(n for n in only(frames, messages.Nack) if n.req_seq == seq)
            assert (nack.reason, nack.detail) == (NackReason.FAILSAFE, FailsafeReason.COMM_TIMEOUT)
            assert sim.outputs().state == SessionState.FAILSAFE
            host.send(messages.Arm(boot_id=out.boot_id))
            host.run()
            assert sim.outputs().state == SessionState.ARMED
            assert sim.outputs().failsafe_reason == FailsafeReason.NONE


def test_lockstep_feedback_answers_each_setpoint() -> None:
    with NativeSim("diffdrive-bts7960") as sim:
        host = HostLink(sim)
        open_and_arm(sim, host, mode=FeedbackMode.LOCKSTEP, watchdog_ms=2000)
        host.send(messages.SetPid(wheel=255, kp=0.0, ki=0.0, kd=0.0, kf=0.0, ks=0.0))  # no plant here
        host.run()
        assert not only(host.run(100_000), messages.Feedback)
        for k in range(10):
            seq = host.send(messages.SetWheelSpeeds(10 * k, -10 * k))
            (fb,) = only(host.run(TICK_US), messages.Feedback)
            assert fb.ack_seq == seq and fb.ack_tick == fb.tick
            assert fb.status & Status.LOCKSTEP


def test_a_reset_is_noticed_through_boot_id_within_a_feedback_period() -> None:
    with NativeSim("diffdrive-tb6612") as sim:
        host = HostLink(sim)
        open_and_arm(sim, host, hz=20)
        old = sim.outputs().boot_id
        host.run(200_000)
        sim.reset()
        host.decoder.reset()
        frames = host.run(50_000)  # one 20 Hz period
        assert isinstance(frames[0].message, messages.Identity) and frames[0].message.reason == IdentityReason.BOOT
        fbs = only(frames, messages.Feedback)
        assert fbs and all(fb.boot_id != old for fb in fbs)
        seq = host.send(messages.Arm(boot_id=old))  # an old session's ARM is never applied
        frames = host.run()
        assert [n.reason for n in only(frames, messages.Nack) if n.req_seq == seq] == [NackReason.NO_SESSION]
        host.send(hello())
        seq = host.send(messages.Arm(boot_id=old))
        frames = host.run()
        assert [n.reason for n in only(frames, messages.Nack) if n.req_seq == seq] == [NackReason.BOOT_ID_MISMATCH]


def test_steering_is_quantised_and_reported() -> None:
    with NativeSim("picar") as sim:
        host = HostLink(sim)
        open_and_arm(sim, host, hz=100, watchdog_ms=2000)
        for mrad, pulse, back in ((300, 1667, 262), (-1571, 1222, -436), (1571, 1833, 524), (100, 1500, 0)):
            host.send(messages.SetAckermann(speed_mm_s=0, steering_mrad=mrad))
            fb = only(host.run(TICK_US), messages.Feedback)[-1]
            assert sim.outputs().steering_us == pulse
            assert fb.steering_mrad == back


# -- configuration ----------------------------------------------------------------------------------
def test_config_survives_a_power_cycle_and_corruption_falls_back_to_defaults() -> None:
    defaults = PROFILES["diffdrive-tb6612"].config
    with NativeSim("diffdrive-tb6612") as sim:
        host = HostLink(sim)
        host.send(hello())
        changed = dataclasses.replace(defaults, accel_limit_mm_s2=1234, feedback_hz=25)
        seq_cfg = host.send(changed)
        seq_pid = host.send(messages.SetPid(wheel=1, kp=2.0, ki=3.0, kd=0.5, kf=1.0, ks=25.0))
        seq_save = host.send(messages.SaveConfig())
        acks = {a.req_seq for a in only(host.run(), messages.Ack)}
        assert {seq_cfg, seq_pid, seq_save} <= acks

        sim.reset()
        host.decoder.reset()
        frames = host.run(100_000)
        assert not only(frames, messages.Log)
        assert all(not (fb.status & Status.CONFIG_DEFAULTS) for fb in only(frames, messages.Feedback))
        host.send(hello())
        seq = host.send(messages.GetConfig())
        host.send(messages.GetPid(wheel=1))
        frames = host.run()
        (cfg,) = only(frames, messages.Config)
        assert cfg.req_seq == seq
        assert {f.name: getattr(cfg, f.name) for f in dataclasses.fields(changed)} == dataclasses.asdict(changed)
        (pid,) = only(frames, messages.Pid)
        assert (pid.kp, pid.ki, pid.kd, pid.kf) == (2.0, 3.0, 0.5, 1.0)

        image = sim.eeprom_read(0x10, 64)
        sim.eeprom_write(0x10 + 30, bytes([image[30] ^ 0x40]))
        sim.reset()
        host.decoder.reset()
        frames = host.run(100_000)
        (log,) = only(frames, messages.Log)
        assert log.level == LogLevel.WARN and "CRC" in log.text and "defaults" in log.text
        assert frames[0].message.reason == IdentityReason.BOOT and frames[1].message == log
        fbs = only(frames, messages.Feedback)
        assert fbs and all(fb.status & Status.CONFIG_DEFAULTS for fb in fbs)
        host.send(hello())
        host.send(messages.GetConfig())
        (cfg,) = only(host.run(), messages.Config)
        assert cfg.accel_limit_mm_s2 == defaults.accel_limit_mm_s2


def test_link_stats_count_what_the_firmware_saw() -> None:
    with NativeSim("diffdrive-tb6612") as sim:
        host = HostLink(sim)
        host.send(hello())
        host.send(messages.Ping(host_time_us=1))
        host.seq += 3  # three frames "lost"
        host.send(messages.Ping(host_time_us=2))
        sim.feed(b"\x05\x11\x22\x00")  # not COBS
        sim.feed(b"\x07\x02\x03\x04\x05\x06\x07\x00")  # COBS, but no valid frame (CRC)
        seq = host.send(messages.GetLinkStats())
        host.send(messages.GetLinkStats(), seq=seq)  # a retry
        frames = host.run()
        stats = only(frames, messages.LinkStats)
        assert len(stats) == 2 and all(s.req_seq == seq for s in stats)
        s = stats[-1]
        assert (s.cobs_errors, s.crc_errors, s.seq_gaps, s.duplicates) == (1, 1, 3, 1)
        assert s.frames_ok == 5
        assert s.bytes_discarded == 3 + 7


# -- robustness ---------------------------------------------------------------------------------------
HOST_TO_MCU = tuple(cls for cls in messages.ALL_MESSAGES if cls.DIRECTION is Direction.HOST_TO_MCU)

actions = st.one_of(
    st.tuples(st.just("garbage"), st.binary(max_size=90)),
    st.tuples(st.just("frame"), rls.frames(rls.messages(HOST_TO_MCU))),
    st.tuples(st.just("frame"), rls.frames()),  # any message, either direction
    st.tuples(st.just("hello"), st.sampled_from(list(FeedbackMode))),
    st.tuples(st.just("arm"), st.booleans()),
    st.tuples(st.just("drive"), st.integers(-700, 700)),
    st.tuples(st.just("time"), st.integers(0, 60_000)),
    st.tuples(st.just("encoder"), st.integers(-500, 500)),
    st.tuples(st.just("reset"), st.none()),
)


@settings(deadline=None)
@given(name=st.sampled_from(PROFILE_NAMES), seed=st.integers(0, 2**32 - 1), steps=st.lists(actions, max_size=40))
def test_random_host_streams_never_break_the_firmware(name: str, seed: int, steps: list[tuple[str, object]]) -> None:
    with NativeSim(name, seed=seed) as sim:
        host = HostLink(sim)
        last_mcu_seq: int | None = None
        for kind, arg in steps:
            if kind == "garbage":
                sim.feed(arg)  # type: ignore[arg-type]
            elif kind == "frame":
                frame = arg
                assert isinstance(frame, Frame)
                host.send(frame.message, seq=frame.seq)
            elif kind == "hello":
                host.send(hello(arg))  # type: ignore[arg-type]
            elif kind == "arm":
                boot_id = sim.outputs().boot_id if arg else 12345
                host.send(messages.Arm(boot_id=boot_id))
            elif kind == "drive":
                v = int(arg)  # type: ignore[call-overload]
                if Capability.ACKERMANN in PROFILES[name].capabilities:
                    host.send(messages.SetAckermann(speed_mm_s=v, steering_mrad=v))
                else:
                    host.send(messages.SetWheelSpeeds(left_mm_s=v, right_mm_s=-v))
            elif kind == "time":
                sim.advance_us(int(arg))  # type: ignore[call-overload]
            elif kind == "encoder":
                sim.add_encoder(0, int(arg))  # type: ignore[call-overload]
            else:
                host.receive()
                sim.reset()
                last_mcu_seq = None
            frames = host.run()
            out = sim.outputs()
            # Always a sane state ...
            assert out.state in (SessionState.IDLE, SessionState.DISARMED, SessionState.ARMED, SessionState.FAILSAFE)
            assert (out.state == SessionState.FAILSAFE) == (out.failsafe_reason != FailsafeReason.NONE)
            assert all(abs(e) <= 1000 for e in (*out.motor_effort, *out.effort_permille))
            if out.state != SessionState.ARMED and not any(out.ramped_mm_s):
                assert all(
                    m != MotorMode.DRIVE or e == 0 for m, e in zip(out.motor_mode, out.motor_effort, strict=True)
                )
            # ... and only well-formed frames on the wire, numbered without gaps.
            assert not host.bad, host.bad
            for f in frames:
                if last_mcu_seq is not None:
                    assert f.seq == (last_mcu_seq + 1) & 0xFF
                last_mcu_seq = f.seq
                if isinstance(f.message, messages.Feedback):
                    assert f.message.boot_id == out.boot_id
