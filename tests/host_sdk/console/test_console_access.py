"""Who may open the console: loopback, tokens, Host and Origin."""

from __future__ import annotations

import pytest

from host_sdk.console.access import Access, is_loopback
from host_sdk.errors import CommandRangeError


def test_loopback_needs_no_token_unless_one_is_given() -> None:
    assert Access.for_host("127.0.0.1").token is None
    assert Access.for_host("localhost").allows(None)
    given = Access.for_host("127.0.0.1", "my-own-token")
    assert not given.allows(None) and not given.allows("wrong-token") and given.allows("my-own-token")


def test_off_loopback_a_random_token_is_made_and_required() -> None:
    a, b = Access.for_host("0.0.0.0"), Access.for_host("0.0.0.0")
    assert a.token and b.token and a.token != b.token and len(a.token) >= 24
    assert not a.allows(None) and not a.allows("") and not a.allows(b.token) and a.allows(a.token)
    assert a.url(8080).startswith("http://127.0.0.1:8080/?token=")
    assert Access.for_host("192.168.1.20", "s3cret-token").url(9000) == "http://192.168.1.20:9000/?token=s3cret-token"


def test_a_short_token_is_refused_naming_it() -> None:
    with pytest.raises(CommandRangeError, match="token"):
        Access.for_host("0.0.0.0", "abc")


@pytest.mark.parametrize(
    ("host", "loop"),
    [
        ("127.0.0.1", True),
        ("127.8.0.1", True),
        ("::1", True),
        ("[::1]", True),
        ("localhost", True),
        ("0.0.0.0", False),
        ("192.168.1.2", False),
        ("robot.local", False),
    ],
)
def test_is_loopback(host: str, loop: bool) -> None:
    assert is_loopback(host) is loop


def test_on_loopback_only_loopback_host_names_are_answered() -> None:
    a = Access.for_host("127.0.0.1")
    assert a.host_ok("127.0.0.1:8080") and a.host_ok("localhost:8080") and a.host_ok("[::1]:8080")
    assert a.host_ok("127.0.0.1:9090")  # an SSH tunnel from another local port
    assert not a.host_ok("evil.example:8080")  # a rebinding attacker's name
    assert not a.host_ok("evil.example") and not a.host_ok(None)
    assert Access.for_host("0.0.0.0").host_ok("robot.local:8080")  # there the token guards


def test_the_websocket_origin_must_be_the_page_itself() -> None:
    assert Access.origin_ok("http://127.0.0.1:8080", "127.0.0.1:8080")
    assert Access.origin_ok(None, "127.0.0.1:8080")  # not a browser: the token alone
    assert not Access.origin_ok("http://evil.example", "127.0.0.1:8080")
    assert not Access.origin_ok("http://127.0.0.1:8081", "127.0.0.1:8080")
    assert not Access.origin_ok("null", "127.0.0.1:8080")


def test_a_token_that_would_not_survive_a_url_is_refused_without_echoing_it() -> None:
    with pytest.raises(CommandRangeError) as exc:
        Access.for_host("0.0.0.0", "ab cd&ef#gh")
    assert "ab cd" not in str(exc.value) and "URL" in str(exc.value)
    assert Access.for_host("0.0.0.0", "my-car_2.token~").token == "my-car_2.token~"
