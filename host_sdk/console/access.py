"""Who may open the console: the address it listens on, the token, the page's origin.

On the loopback address (the default) only programs on the robot itself can connect, and a token is
needed only if one was given. On any other address a token is required from every client, loopback
ones included: a random one per start unless the user gives one, printed in a ready-to-open URL
(`http://robot.local:8080/?token=...`, as Jupyter does). The page's first request carries it in the
URL; the answer sets it as a cookie for the page's own requests (scripts, WebSocket). Tokens are
compared in constant time (`hmac.compare_digest`).

A browser lets any page it shows open a WebSocket to any address, the robot's included; the
WebSocket's `Origin` must therefore be the console's own. The `Host` a request names must be one the
console answers to on loopback, so a name that resolves to 127.0.0.1 for an attacker's page (DNS
rebinding) is refused there too.
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
from dataclasses import dataclass
from urllib.parse import urlsplit

from host_sdk.errors import CommandRangeError

COOKIE = "roverlink_console_token"
TOKEN_CHARACTERS = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_.~")
LOOPBACK_NAMES = ("localhost",)


def is_loopback(host: str) -> bool:
    """`host` (an address or "localhost") is this machine only."""
    if host.lower() in LOOPBACK_NAMES:
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


@dataclass(frozen=True, slots=True)
class Access:
    host: str
    """The address the console listens on."""
    token: str | None
    """What every client must present (None: loopback without a token)."""

    @classmethod
    def for_host(cls, host: str, token: str | None = None) -> Access:
        """The rule for listening on `host`: a given token always counts; off loopback a random one
        is made when none is given."""
        if token is not None and (len(token) < 8 or not set(token) <= TOKEN_CHARACTERS):
            # the value itself is a secret: it is described, not echoed
            unsafe = not set(token) <= TOKEN_CHARACTERS
            shown = "(hidden) with characters a URL changes" if unsafe else f"(hidden) of {len(token)} characters"
            raise CommandRangeError("token", shown, "at least 8 of A-Z a-z 0-9 - _ . ~ (it goes in a URL as it is)")
        if token is None and not is_loopback(host):
            token = secrets.token_urlsafe(24)
        return cls(host, token)

    def allows(self, presented: str | None) -> bool:
        """The token a request presented (URL, cookie or header) is the right one."""
        if self.token is None:
            return True
        if presented is None:
            return False
        return hmac.compare_digest(presented.encode(), self.token.encode())

    def host_ok(self, host_header: str | None) -> bool:
        """The `Host` a request names is one this console answers to. Off loopback the token is the
        guard (the robot's name on the network is not known here); on loopback only loopback names,
        on any port (an SSH tunnel's local port may differ from the console's)."""
        if not is_loopback(self.host):
            return True
        if not host_header:
            return False
        name = host_header.rpartition(":")[0] if not host_header.endswith("]") else host_header
        return is_loopback(name or host_header)

    @staticmethod
    def origin_ok(origin: str | None, host_header: str | None) -> bool:
        """A WebSocket's `Origin` is the console's own page (the same host and port the request
        names). A client that is not a browser sends none and is held to the token alone."""
        if origin is None:
            return True
        parts = urlsplit(origin)
        return parts.scheme in ("http", "https") and host_header is not None and parts.netloc == host_header

    def url(self, port: int, host: str | None = None) -> str:
        """The URL to open, with the token in it."""
        name = host or self.host
        if name in ("0.0.0.0", "::"):
            name = "127.0.0.1" if name == "0.0.0.0" else "[::1]"
        elif ":" in name and not name.startswith("["):
            name = f"[{name}]"
        query = f"?token={self.token}" if self.token else ""
        return f"http://{name}:{port}/{query}"
