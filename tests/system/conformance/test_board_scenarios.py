"""The conformance suite's board scenarios on three backends (see test_scenarios.py): reliable ARM,
EEPROM persistence and fallback (identical bytes); encoder faults, the ESC and the LEDs (timing
within a tick, pins as ground truth)."""

from __future__ import annotations

import pytest
from conformance_backends import BACKENDS, Backend
from conformance_board_scenarios import LED_TOL_MS
from conformance_runner import PROFILE, reference, run, run_fresh
from conformance_scenarios import TICK_MS, answer, decode

from host_sdk import messages
from protocol.generated.enums import FailsafeReason, LightsMode, NackReason, Status
from protocol.generated.profiles import PROFILES


# -- reliable ARM, EEPROM persistence and fallback: identical bytes ------------------------------------------
def test_duplicate_arm(tb6612: Backend) -> None:
    got = run(tb6612, "duplicate_arm")
    ref = reference("duplicate_arm", backend=tb6612.name)
    assert got == ref
    # What the reference itself must show (control.md 1-2): both retries counted, the late one not
    # applied (the setpoint after it is refused with the latched reason), the drive uninterrupted.
    assert got["arm"] == got["dup"] and got["wrong_boot_id"] == got["wrong_boot_id_dup"]
    assert got["duplicates"] == 2 and got["failsafe_reason"] == FailsafeReason.COMM_TIMEOUT
    assert got["still_failsafe"] and got["driving_throughout"]
    assert answer(got["dup_not_applied"]) == ("NACK", NackReason.FAILSAFE, FailsafeReason.COMM_TIMEOUT)
    assert answer(got["wrong_boot_id"]) == ("NACK", NackReason.BOOT_ID_MISMATCH, 0)
    assert answer(got["arm_while_armed"])[0] == "ACK" and answer(got["rearm"])[0] == "ACK"


NO_STORAGE = "the Pico keeps no configuration (docs/firmware.md, Raspberry Pi Pico): no_storage instead"


def test_save_config_survives_a_reset(tb6612: Backend) -> None:
    if tb6612.name == "rp2040":
        pytest.skip(NO_STORAGE)
    got = run(tb6612, "save_config")
    ref = reference("save_config", backend=tb6612.name)
    assert got == ref
    assert answer(got["save_armed"]) == ("NACK", NackReason.ARMED, 0)
    assert answer(got["save"])[0] == "ACK" and got["defaults_bit_cleared"]
    assert got["boot_logs"] == []  # a good image: no LOG at boot
    assert all(not s & Status.CONFIG_DEFAULTS for s in got["boot_status"])  # type: ignore[attr-defined]
    config = decode(got["config"])
    assert isinstance(config, messages.Config)
    assert (config.accel_limit_mm_s2, config.watchdog_ms, config.feedback_hz) == (1500, 300, 25)
    pid1, pid0 = decode(got["pid1"]), decode(got["pid0"])
    assert isinstance(pid1, messages.Pid) and isinstance(pid0, messages.Pid)
    assert (pid1.kp, pid1.ki, pid1.kf) == (1.25, 5.5, 1.625) and pid0.kp == PROFILES[PROFILE].pid.kp


def test_a_board_without_storage_refuses_save_config_and_boots_on_defaults() -> None:
    got = run_fresh("rp2040", "no_storage")
    assert got == reference("no_storage", backend="rp2040")
    assert answer(got["save"]) == ("NACK", NackReason.UNSUPPORTED, 0)
    assert answer(got["set_config"])[0] == "ACK"
    assert got["after_reset_is_defaults"]  # the SET_CONFIG did not outlive the reset


@pytest.mark.parametrize("scenario", ["config_fallback:crc", "config_fallback:invalid"])
@pytest.mark.parametrize("backend_name", BACKENDS)
def test_bad_eeprom_image_falls_back_to_defaults(backend_name: str, scenario: str) -> None:
    if backend_name == "rp2040":
        pytest.skip(NO_STORAGE)
    got = run_fresh(backend_name, scenario)
    ref = reference(scenario, backend=backend_name)
    assert got == ref
    expected = {
        "config_fallback:crc": "config: EEPROM CRC error, using defaults",
        "config_fallback:invalid": "config: EEPROM values invalid, using defaults",
    }
    assert got["log_text"] == expected[scenario] and len(got["logs"]) == 1  # type: ignore[arg-type]
    assert int(got["status"]) & Status.CONFIG_DEFAULTS  # type: ignore[call-overload]
    config = decode(got["config"])
    assert isinstance(config, messages.Config)
    assert {f.name: getattr(config, f.name) for f in messages.SetConfig.FIELDS} == PROFILES[PROFILE].config.fields()


# -- faults, ESC, LEDs: timing within a tick, pins as ground truth --------------------------------------------
# Encoder fault: the host-side time from the disconnect to the first FEEDBACK reporting FAILSAFE
# agrees with the reference within one control tick (the disconnect falls anywhere in a tick: the
# tick grid's phase against the host's clock differs between backends) plus 5 ms (a FEEDBACK frame
# is 3.5 ms on the wire at 115200 baud, and the backends deliver it more or less paced).
ENCODER_FAULT_TOL_MS = TICK_MS + 5


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_encoder_fault(backend_name: str) -> None:
    got = run_fresh(backend_name, "encoder_fault")
    ref = reference("encoder_fault", backend=backend_name)
    print(
        f"\n  {backend_name}: encoder fault {got['delay_ms']:.0f} ms after the disconnect (ref {ref['delay_ms']:.0f})"
    )
    # Exactly 50 ticks without a count change at |u| >= 300 (control.md 4.8), on every backend.
    assert got["stall_ticks"] == 50
    assert abs(got["delay_ms"] - ref["delay_ms"]) <= ENCODER_FAULT_TOL_MS  # type: ignore[operator]
    assert got["reason"] == FailsafeReason.ENCODER_FAULT
    assert got["status"] == Status.SESSION | Status.FAILSAFE | Status.ENCODER_FAULT
    for key in ("effort_zero", "latched_nack", "still_latched", "rearm", "cleared", "driving_again"):
        assert got[key] == ref[key], key
    assert answer(got["latched_nack"]) == ("NACK", NackReason.FAILSAFE, FailsafeReason.ENCODER_FAULT)
    assert got["effort_zero"] and got["still_latched"] and got["cleared"] and got["driving_again"]


# ESC window: the drive is released in tick esc_arm_ms / 10 ms exactly on every backend (the tick
# grid starts at the boot). On the pins, the first non-neutral pulse, measured from the firmware's
# tick 0 as the host sees it (tick_origin), agrees with the reference within 5 ms: up to the
# FEEDBACK line time that tick_origin carries (3.5 ms) plus the 1 ms the pins are sampled at.
ESC_RELEASE_TOL_MS = 5


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_esc_arming_window(backend_name: str) -> None:
    got = run_fresh(backend_name, "esc_arming")
    ref = reference("esc_arming", backend=backend_name)
    c = PROFILES["picar"].config
    print(f"\n  {backend_name}: ESC released {got['release_ms']:.1f} ms after boot (ref {ref['release_ms']:.1f})")
    assert got["release_tick"] == c.esc_arm_ms // TICK_MS
    assert got["window_esc_us"] == [c.esc_neutral_us]  # neutral from boot, nothing else
    assert abs(got["release_ms"] - ref["release_ms"]) <= ESC_RELEASE_TOL_MS  # type: ignore[operator]
    assert abs(got["release_ms"] - c.esc_arm_ms) <= ESC_RELEASE_TOL_MS  # type: ignore[operator]
    # The pins change in the tick whose FEEDBACK first reports the effort (no later than its line time).
    assert 0 <= got["pins_to_feedback_ms"] <= ESC_RELEASE_TOL_MS  # type: ignore[operator]
    for key in ("hello", "arm", "nacks", "window_servo_us", "first_pulse_us", "first_effort", "window_feedback"):
        assert got[key] == ref[key], key
    for key in ("window_applied", "driving_after", "disarm", "disarmed_pins"):
        assert got[key] == ref[key], key
    # What the reference itself must show (control.md 5): ARM accepted, no setpoint refused, the
    # setpoint applied (ack_tick) and the servo steered while the ESC stays at neutral, then driven.
    assert answer(got["arm"])[0] == "ACK" and got["nacks"] == []
    assert got["window_applied"] and got["driving_after"]
    assert got["window_servo_us"] != [c.servo_min_us + 9000 * (c.servo_max_us - c.servo_min_us) // 18000]
    assert got["esc_after_us"] > c.esc_neutral_us  # type: ignore[operator]
    assert answer(got["disarm"])[0] == "ACK" and got["disarmed_pins"][:2] == (c.esc_neutral_us, 1500)  # type: ignore[index]


LED_EXPECTED = {
    # docs/firmware.md, Lights: FRONT = 3, REAR = 12, LEFT = 5, RIGHT = 10, ALL = 15.
    "idle": [3, 12],
    "straight": [0],
    "left": [0, 5],
    "right": [0, 10],
    "rotate": [0, 15],
    "nearly_straight": [0],
    "stop": [0],
    "failsafe": [0, 15],
    "disarmed": [3, 12],
}


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_turn_signal_leds(backend_name: str) -> None:
    got = run_fresh(backend_name, "leds")
    ref = reference("leds", backend=backend_name)
    assert ref["masks"] == LED_EXPECTED
    assert got["masks"] == ref["masks"]
    changes: list[tuple[float, int]] = got["changes"]  # type: ignore[assignment]
    ref_changes: list[tuple[float, int]] = ref["changes"]  # type: ignore[assignment]
    assert [m for _, m in changes] == [m for _, m in ref_changes]
    worst = max(abs(t - rt) for (t, _), (rt, _) in zip(changes, ref_changes, strict=True))
    print(f"\n  {backend_name}: {len(changes)} LED changes, worst {worst:.0f} ms from the reference's")
    assert worst <= LED_TOL_MS


HOST_LIGHTS_EXPECTED = {
    # MANUAL: front left steady (1), rear left slow (4), rear right fast (8): every mix of the two blinks.
    "auto": [3, 12],
    "off": [0],
    "manual": [1, 5, 9, 13],
    "manual_armed": [1, 5, 9, 13],
    "failsafe": [0, 15],
    "new_session": [3, 12],
}


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_host_lights(backend_name: str) -> None:
    got = run_fresh(backend_name, "host_lights")
    ref = reference("host_lights", backend=backend_name)
    assert ref["masks"] == HOST_LIGHTS_EXPECTED
    assert got == ref
    # What the reference itself must show: each mode applied and reported, lit as the pins showed it.
    assert answer(got["idle_set"]) == ("NACK", NackReason.NO_SESSION, 0)
    assert answer(got["set_off"])[0] == "ACK" and answer(got["set_manual"])[0] == "ACK"
    states = {k: decode(v) for k, v in got.items() if k.startswith("state_") and isinstance(v, str)}
    reported = {k: (s.mode, s.steady, s.slow, s.fast, s.lit) for k, s in states.items()}  # type: ignore[attr-defined]
    manual = (LightsMode.MANUAL, 1, 4, 8, 13)  # 3 ticks into a period: both blinks on
    assert reported == {
        "state_auto": (LightsMode.AUTO, 0, 0, 0, 3),
        "state_off": (LightsMode.OFF, 0, 0, 0, 0),
        "state_manual": manual,
        "state_manual_armed": manual,
        "state_new_session": (LightsMode.AUTO, 0, 0, 0, 3),
    }
    assert got["state_failsafe"] == manual[:4]


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_host_lights_refused_without_turn_signals(backend_name: str) -> None:
    got = run_fresh(backend_name, "host_lights_unsupported")
    assert got == reference("host_lights_unsupported", backend=backend_name)
    assert answer(got["set"]) == answer(got["get"]) == ("NACK", NackReason.UNSUPPORTED, 0)
