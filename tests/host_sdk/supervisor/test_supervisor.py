"""The supervisor on the emulator's virtual clock: a cut link, a board reset and an ARM nobody answers
become state (link lost since T, board reset, a refusal), never an exception; the robot is armed only
when the program asks, after each of them."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from urllib.parse import quote

import pytest

from host_sdk import Robot
from host_sdk.supervisor import Health, Supervisor


def supervised(faults: str = "") -> Supervisor:
    url = "emu://diffdrive-tb6612?clock=virtual&seed=3"
    if faults:
        url += "&faults=" + quote(faults)
    return Supervisor(Robot.connect(url))


def run(sup: Supervisor, until_s: float, *, drive: bool = True) -> list[tuple[float, Health]]:
    """Step a program's loop (drive while armed) until `until_s` on the robot's clock; each health."""
    seen = []
    while sup.now() < until_s:
        health = sup.health()
        seen.append((sup.now(), health))
        if drive and health.armed:
            assert sup.drive(0.2, 0.0) or not sup.health().armed
        sup.sleep(0.05)
    return seen


def first(seen: list[tuple[float, Health]], check: Callable[[Health], bool]) -> tuple[float, Health]:
    return next((t, h) for t, h in seen if check(h))


def test_a_cut_link_is_lost_at_once_never_armed_and_the_failsafe_shows_when_it_is_back() -> None:
    with supervised("cut@2-4") as sup:
        assert sup.arm()
        seen = run(sup, 6.0)
        t_lost, lost = first(seen, lambda h: h.link == "lost")
        assert 2.0 < t_lost < 2.0 + 1.0  # the truth within a second
        assert lost.since_s is not None and lost.since_s == t_lost and lost.halt_why == "link lost"
        assert all(not h.armed for t, h in seen if 2.0 + 1.0 < t < 4.0)  # never "armed" while it is down
        assert all(h.link == "lost" and h.stale for t, h in seen if 2.0 + 1.0 < t < 4.0)
        banner = lost.banner()
        assert banner is not None and banner.level == "error" and "link lost since" in banner.text
        t_back, back = first(seen, lambda h: h.link == "up" and h.failsafe is not None)
        assert 4.0 < t_back < 5.0 and back.failsafe == "COMM_TIMEOUT" and not back.armed
        assert all(not h.armed for t, h in seen if t > 2.0 + 1.0)  # it waits for the program to arm
        assert back.since_s is None
        assert sup.arm() and sup.health().armed and sup.health().failsafe is None


def test_an_arm_nobody_answers_is_a_refusal_kept_until_dismissed() -> None:
    with supervised("cut@1") as sup:
        run(sup, 1.05)
        assert sup.health().link == "up"  # the cut is not seen yet: the ARM goes out and times out
        assert not sup.arm()
        refusal = sup.health().refusals[-1]
        assert refusal.what == "ARM" and "no answer" in refusal.text
        run(sup, 3.0)
        assert sup.health().link == "lost"
        assert not sup.arm()  # still tried (the board may hear it), and refused again
        refusals = sup.health().refusals
        assert len(refusals) == 2 and "no answer" in refusals[-1].text
        sup.dismiss(refusals[0].id)
        assert [r.id for r in sup.health().refusals] == [refusals[1].id]


def test_a_board_reset_is_shown_until_armed_and_arming_takes_the_new_boot() -> None:
    with supervised("reset@2") as sup:
        old = sup.robot.identity.boot_id
        assert sup.arm()
        seen = run(sup, 5.0, drive=False)  # nothing took the reset: arm() meets it first
        t_reset, reset = first(seen, lambda h: h.reset is not None)
        assert 2.0 < t_reset < 2.0 + 2.5  # the bootloader's silence, then the boot announcement
        assert reset.reset is not None and reset.reset.old_boot_id == old and not reset.armed
        assert reset.halts > seen[0][1].halts
        now = sup.health()
        banner = now.banner()
        assert now.link == "up" and banner is not None and "board reset at" in banner.text
        assert sup.arm()  # the reset not yet raised is taken as seen: the new boot is armed
        after = sup.health()
        assert after.armed and after.reset is None and sup.robot.identity.boot_id != old
        assert after.banner() is None


def test_drive_and_disarm_say_what_happened_without_raising() -> None:
    with supervised("cut@1") as sup:
        assert not sup.drive(0.1, 0.0)  # not armed: False, and a halt noted
        assert sup.health().halt_why == "not armed"
        assert sup.arm()
        run(sup, 2.0)
        assert not sup.disarm()  # nobody answers
        assert sup.health().refusals[-1].what == "DISARM"


def test_the_sdk_docs_supervisor_section_runs_as_documented(capsys: pytest.CaptureFixture[str]) -> None:
    doc = (Path(__file__).resolve().parents[3] / "docs" / "sdk.md").read_text(encoding="utf-8")
    section = doc[doc.index("## Riding through failures") : doc.index("## Errors")]
    code = re.findall(r"```python\n(.*?)```", section, re.S)[0]
    exec(compile(code, "docs/sdk.md", "exec"), {})
    claimed = re.search(r"print\(.*\)\s+# (.*)", code)
    assert claimed and capsys.readouterr().out.strip() == claimed.group(1)


def test_a_failsafe_banner_words_the_reason_as_the_sdk_does_everywhere() -> None:
    from host_sdk.failsafe import failsafe_meaning
    from protocol.generated.enums import FailsafeReason

    def health(reason: str) -> Health:
        return Health(
            link="up",
            since_s=None,
            since_wall=None,
            now_s=1.0,
            armed=False,
            state="failsafe",
            failsafe=reason,
            reset=None,
            refusals=(),
            busy=None,
            halts=1,
            halt_why="",
            port_error="",
            attempts=0,
            url="emu://x",
        )

    banner = health("ENCODER_FAULT").banner()
    words = failsafe_meaning(FailsafeReason.ENCODER_FAULT)
    assert banner is not None and banner.text == f"failsafe ENCODER_FAULT: {words}" and "blocked" in words
    unknown = health("SOMETHING_NEW").banner()
    assert unknown is not None and unknown.text == "failsafe SOMETHING_NEW: the board stopped the motors"
