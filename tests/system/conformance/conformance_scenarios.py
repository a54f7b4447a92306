"""The conformance suite's steps and its link scenarios (boot, handshake, arming, failsafe, reset,
reliable requests, lockstep, driving): each runs on a backend and returns what is compared."""

from __future__ import annotations

import dataclasses
import itertools
import math

from conformance_backends import Host, base_profile, wire

from host_sdk import messages
from host_sdk.framing import Frame, FrameDecoder
from protocol.codec.message import Message
from protocol.generated.constants import SPEC_HASH
from protocol.generated.enums import Capability, FeedbackMode, IdentityReason, Status
from protocol.generated.profiles import PROFILES
from tests.support.hostlink import hello

TICK_MS = 10
BOOT_TIMEOUT_MS = 2500


def decode(hex_frame: object) -> Message:
    """A frame from ``wire()`` back to its message."""
    assert isinstance(hex_frame, str)
    frames = [e for e in FrameDecoder().feed(bytes.fromhex(hex_frame)) if isinstance(e, Frame)]
    assert len(frames) == 1
    return frames[0].message


def answer(hex_frame: object) -> tuple[str, int, int]:
    """("ACK", 0, 0) or ("NACK", reason, detail)."""
    m = decode(hex_frame)
    if isinstance(m, messages.Nack):
        return "NACK", m.reason, m.detail
    assert isinstance(m, messages.Ack), m
    return "ACK", 0, 0


def boot(h: Host) -> messages.Identity:
    _, ident = h.wait_for(messages.Identity, BOOT_TIMEOUT_MS, lambda m: m.reason == IdentityReason.BOOT)
    assert isinstance(ident, messages.Identity)
    return ident


def tick_origin(h: Host) -> int:
    """The host time of the firmware's tick 0 (its boot), as its FEEDBACK shows it: the arrival of
    the first FEEDBACK of tick >= 5 (the first ticks may run late behind the boot's EEPROM write)
    minus that many ticks. Later than the true instant by up to that FEEDBACK's line time (3.5 ms
    at 115200 baud). Not the boot IDENTITY's arrival: how long after tick 0 it goes out differs
    between backends (the model starts its clock before the boot counter's EEPROM write, the C++
    core after it; the native build's EEPROM takes no time, simavr's 3.4 ms per byte)."""
    for t, m in h.timed(Message):
        if isinstance(m, messages.Feedback) and m.tick >= 5:
            return t - m.tick * TICK_MS * 1000
    raise AssertionError(f"{h.b.name}: no FEEDBACK of tick >= 5 yet")


def open_session(h: Host, mode: FeedbackMode = FeedbackMode.STREAM, arm: bool = True) -> messages.Identity:
    b = boot(h)
    ident = h.request(hello(mode))
    assert isinstance(ident, messages.Identity) and ident.reason == IdentityReason.HELLO_ACCEPTED
    if arm:
        ack = h.request(messages.Arm(b.boot_id))
        assert isinstance(ack, messages.Ack), ack
    return ident


# -- scenarios: each returns what is compared ----------------------------------------------------------
def sc_boot(h: Host) -> dict[str, object]:
    """The boot IDENTITY and, on a board with storage, the LOG that a blank one holds no
    configuration; a board without storage (the Pico) sends none (log None)."""
    ident = boot(h)
    if ident.capabilities & Capability.EEPROM:
        log: str | None = wire(h.wait_for(messages.Log, 200)[1])
    else:
        h.run_ms(200)
        log = None if not h.since(messages.Log, 0) else "unexpected LOG"
    return {"identity": wire(dataclasses.replace(ident, robot_name="")), "name": ident.robot_name, "log": log}


def sc_handshake(h: Host) -> dict[str, object]:
    boot(h)
    rejected = h.request(hello(spec_hash=SPEC_HASH ^ 0xFFFF))
    accepted = h.request(hello())
    assert isinstance(rejected, messages.Identity) and isinstance(accepted, messages.Identity)
    return {
        "rejected_reason": rejected.reason,
        "accepted_reason": accepted.reason,
        "rejected": wire(dataclasses.replace(rejected, robot_name="")),
        "accepted": wire(dataclasses.replace(accepted, robot_name="")),
    }


def sc_arm_and_refusals(h: Host) -> dict[str, object]:
    b = boot(h)
    out: dict[str, object] = {}
    out["setpoint_idle"] = wire(h.request(messages.SetWheelSpeeds(100, 100)))
    out["arm_idle"] = wire(h.request(messages.Arm(b.boot_id)))
    h.request(hello())
    out["setpoint_disarmed"] = wire(h.request(messages.SetWheelSpeeds(100, 100)))
    out["arm_wrong_boot"] = wire(h.request(messages.Arm(b.boot_id ^ 1)))
    out["arm"] = wire(h.request(messages.Arm(b.boot_id)))
    out["too_fast"] = wire(h.request(messages.SetWheelSpeeds(100, 30000)))
    out["disarm"] = wire(h.request(messages.Disarm()))
    return out


def sc_failsafe(h: Host) -> dict[str, object]:
    ident = open_session(h)
    last = 0
    for _ in range(30):
        last = h.send(messages.SetWheelSpeeds(200, 200))
        h.run_ms(TICK_MS)
    t_last = h.sent_at[last]
    t_fs, fb = h.wait_for(messages.Feedback, 1000, lambda m: bool(m.status & Status.FAILSAFE))
    assert isinstance(fb, messages.Feedback)
    latched = h.request(messages.SetWheelSpeeds(100, 100))
    h.run_ms(100)
    still = [m for _, m in h.since(messages.Feedback, h.b.now_us - 50_000)]
    rearm = h.request(messages.Arm(ident.boot_id))
    seq = h.send(messages.SetWheelSpeeds(100, 100))
    _, after = h.wait_for(messages.Feedback, 5 * TICK_MS, lambda m: m.ack_seq == seq)
    return {
        "delay_ms": (t_fs - t_last) / 1000,
        "reason": fb.failsafe_reason,
        "effort_zero": fb.effort_permille == (0, 0),
        "latched_nack": wire(latched),
        "still_failsafe": all(m.status & Status.FAILSAFE for m in still if isinstance(m, messages.Feedback)),
        "rearm": wire(rearm),
        "after_rearm": bool(after.status & Status.ARMED),  # type: ignore[attr-defined]
    }


def sc_reset_mid_session(h: Host) -> dict[str, object]:
    first = open_session(h)
    for _ in range(10):
        h.send(messages.SetWheelSpeeds(150, 150))
        h.run_ms(TICK_MS)
    h.b.reset()
    second = boot(h)
    nack = h.request(messages.SetWheelSpeeds(100, 100))
    stale_arm = h.request(messages.Arm(first.boot_id))
    return {
        "new_boot_id": second.boot_id != first.boot_id,
        "boot": wire(dataclasses.replace(second, robot_name="")),
        "nack": wire(nack),
        "stale_arm": wire(stale_arm),
    }


def sc_reliable_config(h: Host) -> dict[str, object]:
    open_session(h, arm=False)
    config = h.request(messages.GetConfig())
    assert isinstance(config, messages.Config)
    fields = {f.name: getattr(config, f.name) for f in messages.SetConfig.FIELDS}
    fields["accel_limit_mm_s2"] = 1500
    new = messages.SetConfig(**fields)
    seq = h.seq
    first = h.request(new, seq=seq)
    h.seq = (seq + 1) & 0xFF
    dup = h.request(new, seq=seq)  # the same (msg_id, seq): answered again, not applied again
    readback = h.request(messages.GetConfig())
    stats = h.request(messages.GetLinkStats())
    bad = dict(fields, steering_min_cdeg=9000, steering_center_cdeg=100)
    invalid = h.request(messages.SetConfig(**bad))
    pid = h.request(messages.GetPid(0))
    assert isinstance(stats, messages.LinkStats)
    return {
        "config": wire(config),
        "ack": wire(first),
        "dup": wire(dup),
        "readback": wire(readback),
        "duplicates": stats.duplicates,
        "invalid": wire(invalid),
        "pid": wire(pid),
    }


def sc_lockstep(h: Host) -> dict[str, object]:
    ident = open_session(h, FeedbackMode.LOCKSTEP)
    h.run_ms(50)
    start = h.b.now_us
    acks = []
    for _ in range(20):
        seq = h.send(messages.SetWheelSpeeds(200, 200))
        _, fb = h.wait_for(messages.Feedback, 3 * TICK_MS, lambda m, s=seq: m.ack_seq == s)
        acks.append(fb.ack_seq == seq)  # type: ignore[attr-defined]
    h.run_ms(100)  # no setpoint: no FEEDBACK (the watchdog fires, then FEEDBACK carries FAILSAFE)
    fbs = h.since(messages.Feedback, start)
    return {
        "mode": ident.feedback_mode,
        "all_answered": all(acks),
        "one_per_setpoint": len([m for _, m in fbs if not m.status & Status.FAILSAFE]) == 20,  # type: ignore[attr-defined]
    }


def sc_lockstep_queue(h: Host) -> dict[str, object]:
    """Lockstep's setpoint queue (LOCKSTEP_QUEUE = 2): setpoints that land between the same two
    ticks are applied one per tick, the oldest first, each answered by its own FEEDBACK; a third
    supersedes the newest, which is never answered. Each burst goes out on the FEEDBACK of the
    setpoint before it, a few milliseconds after its tick, so the burst lands before the next."""
    open_session(h, FeedbackMode.LOCKSTEP)
    h.run_ms(50)
    out: dict[str, object] = {}
    for key, burst in (("two", 2), ("three", 3)):
        lead = h.send(messages.SetWheelSpeeds(100, 100))
        t, _ = h.wait_for(messages.Feedback, 3 * TICK_MS, lambda m, s=lead: m.ack_seq == s)
        seqs = [h.send(messages.SetWheelSpeeds(100 + 10 * k, 100)) for k in range(1, burst + 1)]
        h.run_ms(5 * TICK_MS)
        fbs = [m for _, m in h.since(messages.Feedback, t + 1) if isinstance(m, messages.Feedback)]
        out[key] = {
            "answered": [seqs.index(m.ack_seq) for m in fbs if m.ack_seq in seqs],
            "tick_gaps": [(b.tick - a.tick) % 65536 for a, b in itertools.pairwise(fbs)],
        }
    return out


def sc_stream_latest_wins(h: Host) -> dict[str, object]:
    """Stream mode: of two setpoints that land between the same two ticks the later is applied and
    the earlier never (a FEEDBACK in every tick shows each tick's ack_seq)."""
    b = boot(h)
    assert isinstance(h.request(hello(FeedbackMode.STREAM, 100)), messages.Identity)
    assert isinstance(h.request(messages.Arm(b.boot_id)), messages.Ack)
    h.run_ms(50)
    h.wait_for(messages.Feedback, 3 * TICK_MS)  # a few milliseconds after its tick
    first = h.send(messages.SetWheelSpeeds(100, 100))
    second = h.send(messages.SetWheelSpeeds(110, 100))
    h.run_ms(5 * TICK_MS)
    acks = [m.ack_seq for _, m in h.since(messages.Feedback, h.sent_at[second]) if isinstance(m, messages.Feedback)]
    return {"first_applied": first in acks, "second_applied": second in acks, "feedbacks": len(acks) >= 4}


LOCKSTEP_STREAM_HZ = 25
"""sc_lockstep_disarmed's feedback_hz: every 4 ticks, unlike the config's 50 Hz."""


def _streamed(fbs: list[tuple[int, Message]], ms: int) -> dict[str, object]:
    """What FEEDBACKs streamed for `ms` show: how many (per second), the tick gaps, the status bits."""
    got = [m for _, m in fbs if isinstance(m, messages.Feedback)]
    return {
        "per_s_ok": abs(len(got) - LOCKSTEP_STREAM_HZ * ms / 1000) <= 1,
        "gaps": sorted({(b.tick - a.tick) % 65536 for a, b in itertools.pairwise(got)}),
        "status": sorted({int(m.status) for m in got}),
    }


def sc_lockstep_disarmed(h: Host) -> dict[str, object]:
    """Lockstep out of ARMED: FEEDBACK streams at feedback_hz (DISARMED, FAILSAFE); while ARMED one
    per applied setpoint and none without. A state change is seen at once: the first tick out of
    ARMED streams."""
    b = boot(h)
    ident = h.request(hello(FeedbackMode.LOCKSTEP, LOCKSTEP_STREAM_HZ))
    assert isinstance(ident, messages.Identity) and ident.feedback_mode == FeedbackMode.LOCKSTEP
    out: dict[str, object] = {}
    t0 = h.b.now_us
    h.run_ms(500)
    out["disarmed"] = _streamed(h.since(messages.Feedback, t0), 500)

    def armed_phase(key: str, setpoints: int) -> None:
        assert isinstance(h.request(messages.Arm(b.boot_id)), messages.Ack)
        t = h.b.now_us  # every FEEDBACK sent before the ACK arrived before it
        h.run_ms(50)  # no setpoint, within the watchdog
        silent = not h.since(messages.Feedback, t)
        answered = 0
        for k in range(setpoints):
            seq = h.send(messages.SetWheelSpeeds(10 * k, 0))
            h.run_ms(2 * TICK_MS)
            fbs = [m for _, m in h.since(messages.Feedback, h.sent_at[seq])]
            answered += int(len(fbs) == 1 and fbs[0].ack_seq == seq)  # type: ignore[attr-defined]
        out[key] = {"silent_without_setpoint": silent, "answered": answered}

    armed_phase("armed", 10)
    assert isinstance(h.request(messages.Disarm()), messages.Ack)
    t_ack = h.b.now_us
    h.run_ms(500)
    fbs = h.since(messages.Feedback, t_ack)
    out["disarmed_again"] = _streamed(fbs, 500)
    out["first_within_a_tick"] = bool(fbs) and fbs[0][0] - t_ack <= (TICK_MS + 5) * 1000
    armed_phase("armed_again", 5)
    t_last = h.b.now_us
    h.run_ms(PROFILES["diffdrive-tb6612"].config.watchdog_ms + 500)
    fbs = h.since(messages.Feedback, t_last)
    assert fbs and isinstance(fbs[0][1], messages.Feedback), f"{h.b.name}: no FEEDBACK after the watchdog"
    t_fs = fbs[0][0]
    out["failsafe_first_reason"] = fbs[0][1].failsafe_reason
    out["failsafe"] = _streamed(h.since(messages.Feedback, t_fs), h.b.now_us // 1000 - t_fs // 1000)
    return out


def sc_drive(h: Host, profile: str) -> dict[str, object]:
    """PID step response and odometry: 1.5 s at a constant setpoint from rest."""
    ident = open_session(h)
    p = PROFILES[base_profile(profile)]
    ackermann = str(p.kinematics) == "ackermann"
    setpoint = 300
    if ackermann:
        # The ESC arming window holds the drive at rest: wait it out (esc_arm_ms from boot), with
        # zero setpoints feeding the watchdog.
        for _ in range(p.config.esc_arm_ms // TICK_MS):
            h.send(messages.SetAckermann(0, 0))
            h.run_ms(TICK_MS)
    t0 = h.b.now_us
    truth0 = h.b.truth()
    speeds: list[tuple[float, int]] = []
    counts: list[tuple[int, ...]] = []
    for _ in range(150):
        if ackermann:
            h.send(messages.SetAckermann(setpoint, 0))
        else:
            h.send(messages.SetWheelSpeeds(setpoint, setpoint))
        h.run_ms(TICK_MS)
    for t, m in h.since(messages.Feedback, t0):
        assert isinstance(m, messages.Feedback)
        if m.ack_tick and m.status & Status.ARMED:
            speeds.append(((t - t0) / 1e6, m.wheel_speed_mm_s[0]))
            counts.append(m.encoder_counts)
    truth = h.b.truth()
    del ident
    return {
        "speeds": speeds,
        "counts": counts,
        "distance_truth_m": math.hypot(truth.x_m - truth0.x_m, truth.y_m - truth0.y_m),
        "edges_truth": truth.encoder_edges,
        "setpoint": setpoint,
    }


TURNS_MM_S = {"turn_then_straight": (0, 60), "reverse_then_straight": (-60, 60)}
"""The turn before the straight run: one wheel standing, or turning backwards, where a wheel
controller without the static-friction feed-forward has no effort learnt for the new direction
and lags its ramp."""


def sc_turn_then_straight(h: Host, turn: tuple[int, int]) -> dict[str, object]:
    """A slow turn held for 2 s, then 300 mm/s on both wheels at once for 1.5 s: the heading the
    plant turned during the straight part (ground truth)."""
    open_session(h)
    for _ in range(200):
        h.send(messages.SetWheelSpeeds(*turn))
        h.run_ms(TICK_MS)
    theta0 = h.b.truth().theta_rad
    for _ in range(150):
        h.send(messages.SetWheelSpeeds(300, 300))
        h.run_ms(TICK_MS)
    return {"veer_deg": math.degrees(math.remainder(h.b.truth().theta_rad - theta0, 2 * math.pi))}
