"""A request in an intact frame holding a value its type does not define, on all three backends.

docs/control.md 1.4: a reliable request (SET_CONFIG's `safe_state` 3 or 255) is a valid frame whose
field is out of range: seq accounting, the watchdog, the duplicate rule, NO_SESSION in IDLE, then
NACK(OUT_OF_RANGE, detail = the first field outside its range or undefined). It must not be dropped
unanswered (the host would retry into a timeout), and it must change nothing. A HELLO with an
undefined feedback_mode is a value error: counted, not answered, and it does not feed the watchdog.

Each backend's answers are compared with fixed expectations and with the Python model's bytes.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

import pytest
from conformance_backends import BACKENDS, Backend, Host, base_profile, make_backend, wire

from host_sdk import messages
from host_sdk.framing import Frame, FrameDecoder
from protocol.codec.message import Delivery, Direction, Message
from protocol.generated import oracle
from protocol.generated.enums import IdentityReason, LightsMode, NackReason, Status
from protocol.generated.profiles import PROFILES
from tests.support import hostlink
from tests.support.hostlink import raw_frame

PROFILE = "diffdrive-tb6612"
SAFE_STATE = [f.name for f in messages.SetConfig.FIELDS].index("safe_state")
WATCHDOG = [f.name for f in messages.SetConfig.FIELDS].index("watchdog_ms")


def with_values(msg: Message, **raw: int) -> bytes:
    """`msg`'s payload with fields holding raw values (that msg itself could not hold)."""
    layout = oracle.PAYLOADS[msg.MSG_ID]
    fields = layout.parse(msg.pack())
    fields.update(raw)
    return bytes(layout.build(fields))


def raw_request(h: Host, cls: type[Message], payload: bytes, seq: int | None = None) -> Message:
    """Sends a hand-made frame of `cls` and returns the ACK or NACK to it."""
    if seq is None:
        seq = h.seq
        h.seq = (seq + 1) & 0xFF
    h.b.write(raw_frame(cls, payload, seq))
    _, answer = h.wait_for(Message, 200, lambda m: isinstance(m, (messages.Ack, messages.Nack)) and m.req_seq == seq)
    return answer


def scenario(h: Host) -> dict[str, object]:
    _, boot = h.wait_for(messages.Identity, 2500, lambda m: m.reason == IdentityReason.BOOT)
    assert isinstance(boot, messages.Identity)
    out: dict[str, object] = {}
    out["idle"] = wire(raw_request(h, messages.SetConfig, with_values(_defaults(h), safe_state=3)))
    # HELLO with an undefined feedback_mode: counted as a value error, never answered.
    hello = hostlink.hello()
    bad_hello_seq = h.seq
    h.seq += 1
    h.b.write(raw_frame(messages.Hello, with_values(hello, feedback_mode=9), bad_hello_seq))
    h.run_ms(50)
    out["bad_hello_answered"] = any(
        isinstance(m, messages.Identity) and m.hello_seq == bad_hello_seq and m.reason != IdentityReason.BOOT
        for _, m in h.timed(Message)
    )
    ident = h.request(hello)
    assert isinstance(ident, messages.Identity) and ident.reason == IdentityReason.HELLO_ACCEPTED
    reply = h.request(messages.GetConfig())
    assert isinstance(reply, messages.Config)
    config = messages.SetConfig(**{f.name: getattr(reply, f.name) for f in messages.SetConfig.FIELDS})
    seq = h.seq
    h.seq = (seq + 1) & 0xFF
    out["safe_state_3"] = wire(raw_request(h, messages.SetConfig, with_values(config, safe_state=3), seq))
    out["retry"] = wire(raw_request(h, messages.SetConfig, with_values(config, safe_state=3), seq))
    out["safe_state_255"] = wire(raw_request(h, messages.SetConfig, with_values(config, safe_state=255)))
    # An earlier field out of range as well: the first one is named.
    both = with_values(config, watchdog_ms=5000, safe_state=255)
    out["both"] = wire(raw_request(h, messages.SetConfig, both))
    after = h.request(messages.GetConfig())
    assert isinstance(after, messages.Config)
    out["unchanged"] = dataclasses.replace(after, req_seq=0) == dataclasses.replace(reply, req_seq=0)
    # ARMED: the refused requests are valid frames, so they feed the watchdog (250 ms).
    ack = h.request(messages.Arm(boot.boot_id))
    assert isinstance(ack, messages.Ack)
    t0 = h.b.now_us
    for _ in range(6):
        raw_request(h, messages.SetConfig, with_values(config, safe_state=7))
        h.run_ms(100)
    feedback = h.since(messages.Feedback, t0)
    out["armed_throughout"] = bool(feedback) and all(
        m.status & Status.ARMED and not m.status & Status.FAILSAFE  # type: ignore[attr-defined]
        for _, m in feedback
    )
    stats = h.request(messages.GetLinkStats())
    assert isinstance(stats, messages.LinkStats)
    out["value_errors"] = stats.value_errors
    out["duplicates"] = stats.duplicates
    out["seq_gaps"] = stats.seq_gaps
    return out


def _defaults(h: Host) -> messages.SetConfig:
    return PROFILES[base_profile(h.b.profile)].config


_references: dict[str, dict[str, object]] = {}


@pytest.fixture(params=BACKENDS)
def backend(request: pytest.FixtureRequest) -> Iterator[Backend]:
    b = make_backend(request.param, PROFILE)
    yield b
    b.close()


@pytest.fixture
def reference(backend: Backend) -> dict[str, object]:
    """The Python model's run on the robot `backend` runs (NAME@pico for rp2040)."""
    if backend.profile not in _references:
        b = make_backend("python", backend.profile)
        try:
            _references[backend.profile] = scenario(Host(b))
        finally:
            b.close()
    return _references[backend.profile]


def _nack(hex_frame: object) -> tuple[int, int, int, int]:
    assert isinstance(hex_frame, str)
    [event] = FrameDecoder().feed(bytes.fromhex(hex_frame))
    assert isinstance(event, Frame) and isinstance(event.message, messages.Nack), event
    m = event.message
    return m.req_id, m.req_seq, m.reason, m.detail


def test_undefined_enum_in_a_reliable_request_is_answered_with_the_field(
    backend: Backend, reference: dict[str, object]
) -> None:
    got = scenario(Host(backend))
    set_config = messages.SetConfig.MSG_ID
    assert _nack(got["idle"])[::2] == (set_config, NackReason.NO_SESSION)
    assert _nack(got["safe_state_3"])[::2] == (set_config, NackReason.OUT_OF_RANGE)
    assert _nack(got["safe_state_3"])[3] == SAFE_STATE
    assert got["retry"] == got["safe_state_3"]
    assert _nack(got["safe_state_255"])[2:] == (NackReason.OUT_OF_RANGE, SAFE_STATE)
    assert _nack(got["both"])[2:] == (NackReason.OUT_OF_RANGE, WATCHDOG)
    assert got["unchanged"] is True
    assert got["bad_hello_answered"] is False
    assert got["armed_throughout"] is True
    # Only the HELLO was a value error; the retry was a duplicate; every frame was accounted.
    assert (got["value_errors"], got["duplicates"]) == (1, 1)
    assert got == reference


def test_the_requests_whose_values_only_the_session_checks_are_vetted_by_it() -> None:
    """The generated dispatcher leaves a reliable request's enum, flag and char values to its
    check_ranges() (docs/codec.md), so the firmware session must run check_ranges() before a
    handler uses such a message: Session::on_frame() does for SET_CONFIG (and SET_PID, which has
    none), Firmware::lights() for SET_LIGHTS. A request added to the spec with such a field needs the same before it is handled."""
    unchecked = {
        cls.NAME
        for cls in messages.ALL_MESSAGES
        if cls.DIRECTION is Direction.HOST_TO_MCU
        and cls.DELIVERY is Delivery.RELIABLE
        and any(f.kind in ("enum", "flags", "str") for f in cls.FIELDS)
    }
    assert unchecked == {"SET_CONFIG", "SET_LIGHTS"}


def lights_scenario(h: Host) -> dict[str, object]:
    """SET_LIGHTS with an undefined mode (and a mask over 15): NACK(OUT_OF_RANGE, the field) on any
    robot, before its capability is looked at; the lights unchanged."""
    h.wait_for(messages.Identity, 2500, lambda m: m.reason == IdentityReason.BOOT)
    h.request(hostlink.hello())
    off = messages.SetLights(LightsMode.OFF, 0, 0, 0)
    out: dict[str, object] = {
        "mode_255": wire(raw_request(h, messages.SetLights, with_values(off, mode=255))),
        "slow_16": wire(raw_request(h, messages.SetLights, with_values(off, slow=16))),
    }
    state = h.request(messages.GetLights())
    out["state"] = wire(state) if isinstance(state, messages.LightsState) else None
    return out


@pytest.mark.parametrize("profile", ["diffdrive-tb6612", "picar"])
@pytest.mark.parametrize("backend_name", BACKENDS)
def test_set_lights_with_an_undefined_mode_is_out_of_range(backend_name: str, profile: str) -> None:
    runs = {}
    for name in ("python", backend_name):
        b = make_backend(name, profile)
        try:
            runs[name] = lights_scenario(Host(b))
        finally:
            b.close()
    got = runs[backend_name]
    assert got == runs["python"]
    assert _nack(got["mode_255"])[2:] == (NackReason.OUT_OF_RANGE, 0)
    assert _nack(got["slow_16"])[2:] == (NackReason.OUT_OF_RANGE, 2)
    if profile == "picar":
        assert got["state"] is None  # NACK(UNSUPPORTED): no turn signals
    else:
        state = FrameDecoder().feed(bytes.fromhex(str(got["state"])))[0]
        assert isinstance(state, Frame) and isinstance(state.message, messages.LightsState)
        assert state.message.mode == LightsMode.AUTO  # unchanged: the power-up mode
