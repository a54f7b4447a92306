"""The conformance suite's board scenarios: duplicate requests, encoder faults, EEPROM save and
fallback, the ESC's arming window, the turn-signal LEDs and the host's choice of them."""

from __future__ import annotations

import dataclasses
import itertools

from conformance_backends import Host, Pins, base_profile, wire
from conformance_scenarios import BOOT_TIMEOUT_MS, TICK_MS, boot, tick_origin

from host_sdk import messages
from protocol.generated.enums import FailsafeReason, IdentityReason, LightsMode, Status
from protocol.generated.profiles import PROFILES
from tests.support.hostlink import hello


def sc_duplicate_arm(h: Host) -> dict[str, object]:
    """ARM is a reliable request: a retry with the same seq is answered again, never applied again
    (control.md 2); a wrong boot_id is refused; ARM while ARMED only feeds the watchdog."""
    b = boot(h)
    h.request(hello())
    out: dict[str, object] = {}
    seq = h.seq
    out["arm"] = wire(h.request(messages.Arm(b.boot_id), seq=seq))
    h.seq = (seq + 1) & 0xFF
    # Silence: the watchdog latches FAILSAFE. Then the host's retry of that ARM arrives late: the
    # same ACK again, but not applied (it would re-arm the robot).
    _, fb = h.wait_for(messages.Feedback, 1000, lambda m: bool(m.status & Status.FAILSAFE))
    out["dup"] = wire(h.request(messages.Arm(b.boot_id), seq=seq))
    h.run_ms(5 * TICK_MS)
    out["dup_not_applied"] = wire(h.request(messages.SetWheelSpeeds(100, 100)))  # NACK(FAILSAFE)
    t_dup = h.b.now_us
    out["still_failsafe"] = all(
        m.status & Status.FAILSAFE  # type: ignore[attr-defined]
        for _, m in h.since(messages.Feedback, t_dup - 5 * TICK_MS * 1000)
    )
    out["rearm"] = wire(h.request(messages.Arm(b.boot_id)))
    # ARM while ARMED and driving: ACK, and the drive goes on (no safe state, no ramp restart).
    for _ in range(20):
        h.send(messages.SetWheelSpeeds(200, 200))
        h.run_ms(TICK_MS)
    t_again = h.b.now_us
    out["arm_while_armed"] = wire(h.request(messages.Arm(b.boot_id)))
    for _ in range(5):
        h.send(messages.SetWheelSpeeds(200, 200))
        h.run_ms(TICK_MS)
    wseq = h.seq
    out["wrong_boot_id"] = wire(h.request(messages.Arm(b.boot_id ^ 0x5A5A), seq=wseq))
    h.seq = (wseq + 1) & 0xFF
    out["wrong_boot_id_dup"] = wire(h.request(messages.Arm(b.boot_id ^ 0x5A5A), seq=wseq))
    for _ in range(5):
        h.send(messages.SetWheelSpeeds(200, 200))
        h.run_ms(TICK_MS)
    around = [m for _, m in h.since(messages.Feedback, t_again - 5 * TICK_MS * 1000)]
    out["driving_throughout"] = bool(around) and all(
        m.status & Status.ARMED and min(m.effort_permille) > 0  # type: ignore[attr-defined]
        for m in around
    )
    stats = h.request(messages.GetLinkStats())
    assert isinstance(stats, messages.LinkStats)
    out["duplicates"] = stats.duplicates
    out["failsafe_reason"] = fb.failsafe_reason  # type: ignore[attr-defined]
    return out


def sc_encoder_fault(h: Host) -> dict[str, object]:
    """An encoder unplugged while driving: |u| >= 300 for 50 ticks without a count change raises
    FAULT(ENCODER_FAULT) (control.md 4.8), latched until re-ARM. FEEDBACK at 100 Hz: one per tick,
    so the fault's tick is seen exactly."""
    b = boot(h)
    ident = h.request(hello(hz=100))
    assert isinstance(ident, messages.Identity) and ident.feedback_hz == 100
    h.request(messages.Arm(b.boot_id))
    for _ in range(100):
        h.send(messages.SetWheelSpeeds(300, 300))
        h.run_ms(TICK_MS)
    t_cut = h.b.now_us
    h.b.disconnect_encoder(0)
    t_fs = 0
    fault: messages.Feedback | None = None
    for _ in range(100):
        h.send(messages.SetWheelSpeeds(300, 300))
        h.run_ms(TICK_MS)
        hits = [(t, m) for t, m in h.since(messages.Feedback, t_cut) if m.status & Status.FAILSAFE]  # type: ignore[attr-defined]
        if hits:
            t_fs, fault = hits[0]  # type: ignore[assignment]
            break
    assert fault is not None, f"{h.b.name}: no FAILSAFE within 1 s of the encoder disconnect"
    fbs = [m for _, m in h.since(messages.Feedback, t_cut - 100_000)]
    before = [m for m in fbs if isinstance(m, messages.Feedback) and m.tick < fault.tick]
    moved = [m.tick for prev, m in itertools.pairwise(before) if m.encoder_counts[0] != prev.encoder_counts[0]]
    h.cursor = len(h.received)
    h.seq = 200  # the setpoints sent until the fault was seen vary with the tick phase: a fixed seq
    latched = h.request(messages.SetWheelSpeeds(300, 300))
    h.run_ms(200)
    still = [m for _, m in h.since(messages.Feedback, h.b.now_us - 150_000)]
    h.b.disconnect_encoder(0, False)
    rearm = h.request(messages.Arm(b.boot_id))
    t_rearm = h.b.now_us
    for _ in range(50):
        h.send(messages.SetWheelSpeeds(300, 300))
        h.run_ms(TICK_MS)
    after = [m for _, m in h.since(messages.Feedback, t_rearm)]
    last = after[-1]
    assert isinstance(last, messages.Feedback)
    return {
        "delay_ms": (t_fs - t_cut) / 1000,
        "stall_ticks": fault.tick - moved[-1],
        "reason": fault.failsafe_reason,
        "status": fault.status & (Status.ARMED | Status.FAILSAFE | Status.ENCODER_FAULT | Status.SESSION),
        "effort_zero": fault.effort_permille == (0, 0),
        "latched_nack": wire(latched),
        "still_latched": all(
            m.status & Status.FAILSAFE and m.failsafe_reason == FailsafeReason.ENCODER_FAULT  # type: ignore[attr-defined]
            for m in still
        ),
        "rearm": wire(rearm),
        "cleared": all(not m.status & (Status.FAILSAFE | Status.ENCODER_FAULT) for m in after),  # type: ignore[attr-defined]
        "driving_again": bool(last.status & Status.ARMED) and min(last.wheel_speed_mm_s) > 150,
    }


def sc_no_storage(h: Host) -> dict[str, object]:
    """A board without storage (the Pico: no EEPROM capability): SAVE_CONFIG is refused with
    NACK(UNSUPPORTED), and after a reset the configuration is the robot's defaults again."""
    boot(h)
    h.request(hello())
    config = h.request(messages.GetConfig())
    assert isinstance(config, messages.Config)
    fields = {f.name: getattr(config, f.name) for f in messages.SetConfig.FIELDS}
    out: dict[str, object] = {"defaults": wire(config)}
    out["set_config"] = wire(h.request(messages.SetConfig(**{**fields, "accel_limit_mm_s2": 1500})))
    out["save"] = wire(h.request(messages.SaveConfig()))
    h.b.reset()
    boot(h)
    h.request(hello())
    after = h.request(messages.GetConfig())
    assert isinstance(after, messages.Config)
    out["after_reset_is_defaults"] = dataclasses.replace(after, req_seq=0) == dataclasses.replace(config, req_seq=0)
    return out


def sc_save_config(h: Host) -> dict[str, object]:
    """SAVE_CONFIG keeps SET_CONFIG and SET_PID across an MCU reset (control.md 2 and 6); refused
    with NACK(ARMED) while armed. Starts from a blank EEPROM (defaults, LOG, CONFIG_DEFAULTS)."""
    b = boot(h)
    _, log = h.wait_for(messages.Log, 200)
    h.request(hello())
    config = h.request(messages.GetConfig())
    assert isinstance(config, messages.Config)
    fields = {f.name: getattr(config, f.name) for f in messages.SetConfig.FIELDS}
    fields.update(accel_limit_mm_s2=1500, watchdog_ms=300, feedback_hz=25, max_wheel_speed_mm_s=500)
    out: dict[str, object] = {"log": wire(log)}
    out["set_config"] = wire(h.request(messages.SetConfig(**fields)))
    out["set_pid"] = wire(h.request(messages.SetPid(wheel=1, kp=1.25, ki=5.5, kd=0.0, kf=1.625, ks=12.5)))
    h.request(messages.Arm(b.boot_id))
    out["save_armed"] = wire(h.request(messages.SaveConfig()))
    h.request(messages.Disarm())
    # The EEPROM writes stall the loop (3.4 ms per changed byte on the board): a long answer.
    out["save"] = wire(h.request(messages.SaveConfig(), timeout_ms=1000))
    _, fb = h.wait_for(messages.Feedback, 100)
    out["defaults_bit_cleared"] = not fb.status & Status.CONFIG_DEFAULTS  # type: ignore[attr-defined]
    h.b.reset()
    h.cursor = len(h.received)
    t_reset = h.b.now_us
    t_boot, second = h.wait_for(messages.Identity, BOOT_TIMEOUT_MS, lambda m: m.reason == IdentityReason.BOOT)
    assert isinstance(second, messages.Identity)
    h.run_ms(100)
    out["boot"] = wire(dataclasses.replace(second, robot_name=""))  # watchdog_ms, feedback_hz: saved
    out["boot_logs"] = [wire(m) for _, m in h.since(messages.Log, t_reset)]
    out["boot_status"] = [
        int(m.status)  # type: ignore[attr-defined]
        for _, m in h.since(messages.Feedback, t_boot)
    ][:3]
    out["hello"] = wire(dataclasses.replace(h.request(hello()), robot_name=""))  # type: ignore[type-var]
    out["config"] = wire(h.request(messages.GetConfig()))
    out["pid0"] = wire(h.request(messages.GetPid(0)))
    out["pid1"] = wire(h.request(messages.GetPid(1)))
    return out


def sc_config_fallback(h: Host) -> dict[str, object]:
    """A boot on an unusable EEPROM image (see EEPROM_IMAGES): the defaults, CONFIG_DEFAULTS and
    the LOG(WARN) that names the cause, right after the boot IDENTITY (control.md 6.1)."""
    ident = boot(h)
    _, log = h.wait_for(messages.Log, 200)
    _, fb = h.wait_for(messages.Feedback, 200)
    h.request(hello())
    config = h.request(messages.GetConfig())
    pid = h.request(messages.GetPid(1))
    logs = [wire(m) for _, m in h.since(messages.Log, 0)]
    return {
        "boot": wire(dataclasses.replace(ident, robot_name="")),
        "log": wire(log),
        "logs": logs,
        "log_text": log.text,  # type: ignore[attr-defined]
        "status": int(fb.status),  # type: ignore[attr-defined]
        "config": wire(config),
        "pid": wire(pid),
    }


def sc_esc_arming(h: Host) -> dict[str, object]:
    """The ESC's arming window (picar, esc_arm_ms = 3 s; control.md 5): neutral pulses from boot,
    ARM accepted and setpoints stored (steering follows at once) but the drive held at neutral
    until esc_arm_ms after boot; then a normal ramp. Pulse widths are read from the pins; FEEDBACK
    at 100 Hz (one per tick) shows in which tick the drive is released."""
    p = PROFILES[base_profile(h.b.profile)].config
    h.pin_log = []
    t_boot, b = h.wait_for(messages.Identity, BOOT_TIMEOUT_MS, lambda m: m.reason == IdentityReason.BOOT)
    assert isinstance(b, messages.Identity)
    out: dict[str, object] = {}
    out["hello"] = wire(dataclasses.replace(h.request(hello(hz=100)), robot_name=""))  # type: ignore[type-var]
    out["arm"] = wire(h.request(messages.Arm(b.boot_id)))
    t_armed = h.b.now_us
    end = t_boot + (p.esc_arm_ms + 600) * 1000
    while h.b.now_us < end:
        h.send(messages.SetAckermann(300, 200))
        h.run_ms(TICK_MS)
    t0 = tick_origin(h)
    pins = h.pin_log
    released = [(t, q) for t, q in pins if t >= t_boot and q.esc_us != p.esc_neutral_us]
    assert released, f"{h.b.name}: the ESC never left neutral"
    t_release, first = released[0]
    fbs = [(t, m) for t, m in h.since(messages.Feedback, t_armed) if isinstance(m, messages.Feedback)]
    t_fb_release, fb_release = next((t, m) for t, m in fbs if m.effort_permille[0] != 0)
    window_end_tick = p.esc_arm_ms // TICK_MS
    fb_window = [m for t, m in fbs if t >= t_armed + 50_000 and m.tick < window_end_tick]
    fb_after = [m for t, m in fbs if t >= h.b.now_us - 100_000]
    out["nacks"] = [wire(m) for _, m in h.since(messages.Nack, t_boot)]
    out["window_esc_us"] = sorted({q.esc_us for t, q in pins if t_boot <= t < t_release})
    out["window_servo_us"] = sorted({q.servo_us for t, q in pins if t_armed + 50_000 <= t < t_release})
    out["release_tick"] = fb_release.tick
    out["release_ms"] = (t_release - t0) / 1000  # pins, from the firmware's tick 0
    out["pins_to_feedback_ms"] = (t_fb_release - t_release) / 1000
    out["first_pulse_us"] = first.esc_us
    out["first_effort"] = fb_release.effort_permille
    out["window_feedback"] = sorted(
        {(int(m.status), m.effort_permille, m.wheel_speed_mm_s, m.steering_mrad) for m in fb_window}
    )
    out["window_applied"] = bool(fb_window) and all(m.ack_tick > 0 for m in fb_window)
    out["driving_after"] = bool(fb_after) and all(
        m.status & Status.ARMED and m.effort_permille[0] > 0 and m.wheel_speed_mm_s[0] > 0 for m in fb_after
    )
    out["esc_after_us"] = pins[-1][1].esc_us
    # DISARM: the safe state (BRAKE) puts the ESC back to neutral at once, the servo to centre.
    h.seq = 200  # the number of setpoints sent so far depends on when the boot was seen
    out["disarm"] = wire(h.request(messages.Disarm()))
    h.run_ms(2)
    out["disarmed_pins"] = dataclasses.astuple(h.b.pins())
    return out


# LED blink phase: the patterns blink from the tick counter (66 ticks: the slow blink is on for
# ticks 1..33 after the boot, the fast one, in FAILSAFE, for 16 ticks of every 33). Motion changes
# are made 85 ms after a slow period starts: 8 ticks from every slow and fast blink edge, so that
# neither a tick's phase nor the line time can move a change across one.
BLINK_PERIOD_MS = 660
SCHEDULE_OFFSET_MS = 85
# An LED change on a backend happens within one control tick (a setpoint arrives anywhere in a
# tick: the next tick applies it) plus 5 ms (up to the FEEDBACK line time tick_origin carries, and
# the 1 ms the pins are sampled at) of the reference's, both measured from the firmware's tick 0.
# The first change, the boot lighting the IDLE pattern, comes at the end of begin(), which on the
# AVR runs 8 ms past the instant it takes as tick 0 (its boot IDENTITY reports uptime_ms = 8): the
# LEDs light 7 to 8 ms after tick 0 there, at tick 0 on the model and the native build.
LED_TOL_MS = TICK_MS + 5
LED_PHASES: tuple[tuple[str, tuple[int, int] | None], ...] = (
    ("idle", None),  # IDLE, then a HELLO: DISARMED
    ("straight", (200, 200)),  # ARM first
    ("left", (100, 300)),
    ("right", (300, 100)),
    ("rotate", (-200, 200)),
    ("nearly_straight", (200, 225)),  # right - left = 25 <= 225 / 8: no signal
    ("stop", (0, 0)),
    ("failsafe", None),  # silence: the watchdog latches FAILSAFE
    ("disarmed", None),  # DISARM
)


def _hold(h: Host, held: tuple[int, int] | None, until_us: int) -> None:
    """Run the board until `until_us`, renewing the setpoint `held` every tick (None: silence)."""
    while h.b.now_us < until_us:
        if held is None:
            h.step()
        else:
            h.send(messages.SetWheelSpeeds(*held))
            h.run_ms(TICK_MS)


def _steady_leds(log: list[tuple[int, Pins]] | None) -> list[tuple[int, int]]:
    """The LED states of a pin log that hold for two samples (see sc_leds)."""
    assert log is not None
    return [(t, q.leds) for (t, q), (_, nxt) in itertools.pairwise(log) if nxt.leds == q.leds]


def sc_leds(h: Host) -> dict[str, object]:
    """Turn signals follow the motion state (docs/firmware.md, Lights), read from the LED pins."""
    h.pin_log = []
    b = boot(h)
    held: tuple[int, int] | None = None  # the setpoint renewed every tick (None: silence)

    h.wait_for(messages.Feedback, 200, lambda m: m.tick >= 5)
    t0 = tick_origin(h)  # the schedule follows the firmware's blink phase, from its tick 0
    starts: list[float] = []
    for i, (name, speeds) in enumerate(LED_PHASES):
        _hold(h, held, t0 + (SCHEDULE_OFFSET_MS + i * BLINK_PERIOD_MS) * 1000)
        starts.append((h.b.now_us - t0) / 1000)
        if name == "straight":
            h.request(hello())
            h.request(messages.Arm(b.boot_id))
        elif name == "disarmed":
            h.request(messages.Disarm())
        held = speeds
    end = t0 + (SCHEDULE_OFFSET_MS + len(LED_PHASES) * BLINK_PERIOD_MS) * 1000
    _hold(h, held, end)
    # The simavr harness snapshots the PORT registers at 1 ms boundaries, which can fall between
    # the four pin writes of one LED update (microseconds apart): a state seen in a single sample
    # is such a snapshot, not something an eye or a camera sees. Patterns change at most once a
    # tick (10 samples), so keep the states that hold for two samples.
    log = h.pin_log
    leds = _steady_leds(log)
    changes: list[tuple[float, int]] = []
    last = 0
    for t, mask in leds:  # from power-up: dark until the boot lights the IDLE pattern
        if mask != last:
            changes.append(((t - t0) / 1000, mask))
            last = mask
    masks: dict[str, list[int]] = {}
    for i, (name, _) in enumerate(LED_PHASES):
        lo = t0 + int((starts[i] + 3 * TICK_MS) * 1000)
        hi = t0 + int((starts[i + 1] if i + 1 < len(starts) else (end - t0) / 1000) * 1000)
        masks[name] = sorted({mask for t, mask in leds if lo <= t < hi})
    return {"changes": changes, "masks": masks}


# The host's lights (SET_LIGHTS): one phase a blink period long each, on the same schedule as
# sc_leds. MANUAL here: front left steady, rear left slow, rear right fast (1 | 4 | 8).
HOST_LIGHTS_MANUAL = messages.SetLights(LightsMode.MANUAL, steady=1, slow=4, fast=8)
HOST_LIGHTS_PHASES: tuple[str, ...] = (
    "auto",  # DISARMED, the power-up mode
    "off",  # SET_LIGHTS(OFF)
    "manual",  # SET_LIGHTS(MANUAL, ...)
    "manual_armed",  # ARM, turning left: the host's lamps, not the left pair
    "failsafe",  # silence: FAILSAFE blinks all four fast in every mode
    "new_session",  # HELLO: back to the power-up mode (DISARMED: front and rear alternate)
)


HOST_LIGHTS_WATCHDOG_MS = PROFILES["diffdrive-tb6612"].config.watchdog_ms
"""The failsafe phase's masks are read from when the watchdog has latched FAILSAFE."""


def sc_host_lights(h: Host) -> dict[str, object]:
    """SET_LIGHTS and GET_LIGHTS (docs/protocol.md, LightsMode): each mode's answer, LIGHTS_STATE
    as the board reports it, and the LED pins in each phase."""
    h.pin_log = []
    b = boot(h)
    out: dict[str, object] = {}
    out["idle_set"] = wire(h.request(messages.SetLights(LightsMode.OFF, 0, 0, 0)))  # NACK(NO_SESSION)
    h.request(hello())
    held: tuple[int, int] | None = None

    h.wait_for(messages.Feedback, 200, lambda m: m.tick >= 5)
    t0 = tick_origin(h)
    starts: list[float] = []
    for i, name in enumerate(HOST_LIGHTS_PHASES):
        _hold(h, held, t0 + (SCHEDULE_OFFSET_MS + i * BLINK_PERIOD_MS) * 1000)
        starts.append((h.b.now_us - t0) / 1000)
        if name == "off":
            out["set_off"] = wire(h.request(messages.SetLights(LightsMode.OFF, 0, 0, 0)))
        elif name == "manual":
            out["set_manual"] = wire(h.request(HOST_LIGHTS_MANUAL))
        elif name == "manual_armed":
            h.request(messages.Arm(b.boot_id))
            held = (100, 300)
        elif name == "failsafe":
            held = None
            h.wait_for(messages.Feedback, 1000, lambda m: bool(m.status & Status.FAILSAFE))
            # The host's choice outlives the failsafe (which lamps are lit depends on when it came).
            state = h.request(messages.GetLights())
            assert isinstance(state, messages.LightsState)
            out["state_failsafe"] = (state.mode, state.steady, state.slow, state.fast)
            continue
        elif name == "new_session":
            h.seq = 100  # the number of setpoints sent so far depends on when the boot was seen
            h.request(hello())
        # 3 ticks in (the request applied, 4 ticks before the fast blink's edge): what the board reports.
        h.run_ms(3 * TICK_MS)
        out[f"state_{name}"] = wire(h.request(messages.GetLights()))
    end = t0 + (SCHEDULE_OFFSET_MS + len(HOST_LIGHTS_PHASES) * BLINK_PERIOD_MS) * 1000
    _hold(h, held, end)
    log = h.pin_log
    leds = _steady_leds(log)
    masks: dict[str, list[int]] = {}
    for i, name in enumerate(HOST_LIGHTS_PHASES):
        settle = HOST_LIGHTS_WATCHDOG_MS if name == "failsafe" else 0
        lo = t0 + int((starts[i] + settle + 3 * TICK_MS) * 1000)
        hi = t0 + int((starts[i + 1] if i + 1 < len(starts) else (end - t0) / 1000) * 1000)
        masks[name] = sorted({mask for t, mask in leds if lo <= t < hi})
    out["masks"] = masks
    return out


def sc_host_lights_unsupported(h: Host) -> dict[str, object]:
    """A robot without TURN_SIGNALS (the PiCar) refuses SET_LIGHTS and GET_LIGHTS: NACK(UNSUPPORTED)."""
    boot(h)
    h.request(hello())
    return {
        "set": wire(h.request(messages.SetLights(LightsMode.AUTO, 0, 0, 0))),
        "get": wire(h.request(messages.GetLights())),
    }
