"""Random host behaviour against a small independent model of the session rules.

The model is written from docs/control.md's prose (not from the generated table the emulator runs),
so a wrong action wiring, NACK reason or latched state in the emulator shows up as a disagreement.
"""

from __future__ import annotations

from hypothesis import settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, invariant, rule

from emulator import Emulator
from host_sdk import enums, messages
from host_sdk.enums import FailsafeReason, NackReason, Status
from protocol.codec.message import Message
from protocol.generated.constants import PROTOCOL_VERSION, SPEC_HASH
from tests.support.hostlink import Host

WATCHDOG_MS = 100
ANSWER_MS = 20  # how long each request rule listens for its answer: the watchdog runs meanwhile


class SessionModel(RuleBasedStateMachine):
    @initialize(seed=st.integers(0, 2**16))
    def boot(self, seed: int) -> None:
        self.emu = Emulator("diffdrive-tb6612", seed=seed)
        self.host = Host(self.emu)
        self.boot_id = self.host.boot().boot_id
        self.state = "IDLE"
        self.reason = FailsafeReason.NONE
        self.quiet_ms = 0  # since the last valid frame: the watchdog's measure

    def _answers(self) -> list[Message]:
        self.quiet_ms = ANSWER_MS  # every request rule sends one valid frame, then listens
        return [
            r.message
            for r in self.host.run(ANSWER_MS / 1000)
            if not isinstance(r.message, (messages.Feedback, messages.Log, messages.Pong))
        ]

    @rule(compatible=st.booleans())
    def hello(self, compatible: bool) -> None:
        spec = SPEC_HASH if compatible else SPEC_HASH ^ 0xFFFF
        self.host.send(messages.Hello(PROTOCOL_VERSION, spec, WATCHDOG_MS, enums.FeedbackMode.STREAM, 100))
        [answer] = self._answers()
        assert isinstance(answer, messages.Identity)
        if compatible:
            assert answer.reason is enums.IdentityReason.HELLO_ACCEPTED
            self.state = "DISARMED"
        else:
            assert answer.reason is enums.IdentityReason.HELLO_REJECTED
            self.state = "IDLE"
        self.reason = FailsafeReason.NONE

    @rule(right_boot=st.booleans())
    def arm(self, right_boot: bool) -> None:
        seq = self.host.send(messages.Arm(self.boot_id if right_boot else self.boot_id ^ 1))
        [answer] = self._answers()
        assert answer.req_seq == seq  # type: ignore[attr-defined]
        if self.state == "IDLE":
            assert isinstance(answer, messages.Nack) and answer.reason is NackReason.NO_SESSION
        elif not right_boot:
            assert isinstance(answer, messages.Nack) and answer.reason is NackReason.BOOT_ID_MISMATCH
        else:
            assert isinstance(answer, messages.Ack)
            self.state, self.reason = "ARMED", FailsafeReason.NONE

    @rule()
    def disarm(self) -> None:
        self.host.send(messages.Disarm())
        [answer] = self._answers()
        assert isinstance(answer, messages.Ack)
        if self.state != "IDLE":
            self.state, self.reason = "DISARMED", FailsafeReason.NONE

    @rule(speed=st.integers(-600, 600))
    def setpoint(self, speed: int) -> None:
        seq = self.host.send(messages.SetWheelSpeeds(speed, -speed))
        answers = self._answers()
        if self.state == "ARMED":
            assert answers == []
            fb = self.host.of(messages.Feedback)[-1]
            assert fb.ack_seq == seq
            return
        [answer] = answers
        assert isinstance(answer, messages.Nack) and answer.req_seq == seq
        expected = {"IDLE": NackReason.NO_SESSION, "DISARMED": NackReason.NOT_ARMED, "FAILSAFE": NackReason.FAILSAFE}
        assert answer.reason is expected[self.state]
        if self.state == "FAILSAFE":
            assert answer.detail == self.reason

    @rule(ms=st.sampled_from([20, 60, WATCHDOG_MS + 20, 300]))
    def silence(self, ms: int) -> None:
        # Silences add up. The firmware fails within one control tick (10 ms) of the watchdog
        # period: a total that ends inside [period, period + 20 ms) is stretched past it, so the
        # model's answer is exact.
        if WATCHDOG_MS <= self.quiet_ms + ms < WATCHDOG_MS + 20:
            ms = WATCHDOG_MS + 20 - self.quiet_ms
        self.host.run(ms / 1000)
        self.quiet_ms += ms
        if self.state == "ARMED" and self.quiet_ms >= WATCHDOG_MS + 20:
            self.state, self.reason = "FAILSAFE", FailsafeReason.COMM_TIMEOUT

    @invariant()
    def firmware_agrees(self) -> None:
        if not hasattr(self, "emu"):
            return
        fw = self.emu.truth.firmware
        assert fw is not None
        assert fw.state.name == self.state
        assert fw.failsafe_reason == self.reason
        status = fw.status
        assert bool(status & Status.SESSION) == (self.state != "IDLE")
        assert bool(status & Status.ARMED) == (self.state == "ARMED")
        assert bool(status & Status.FAILSAFE) == (self.state == "FAILSAFE")
        if self.state != "ARMED":
            assert fw.efforts_permille == (0, 0) and fw.targets_mm_s == (0.0, 0.0)


SessionModel.TestCase.settings = settings(max_examples=25, stateful_step_count=20, deadline=None)
test_session_rules_against_a_model = SessionModel.TestCase
