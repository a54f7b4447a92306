"""URL schemes the SDK does not own, opened by registered plugins (as python-can finds its interfaces).

A package registers a scheme in the ``roverlink.transports`` entry point group:

    [project.entry-points."roverlink.transports"]
    emu = "emulator.transport.inprocess:open_url"

The target is called as ``open_url(url, baud)`` and returns an object with the Transport methods
(`read(timeout_s)`, `write(data)`, `close()`, `clock()`) and attributes (`url`, `virtual`, and
optionally `profile`, `robot_file`, `device`, `endpoints`, `locked()`). It need not import the SDK:
`PluginTransport` adapts it, turning an OSError from its I/O into TransportError. A ValueError it
raises while opening (a bad URL parameter, an unknown profile, a robot file's problems) becomes a
CommandRangeError naming the `url` with the plugin's explanation; other RoverLinkErrors pass
through; anything else becomes a TransportError.
"""

from __future__ import annotations

import importlib.metadata
from collections.abc import Callable, Mapping
from typing import Any, Protocol

from host_sdk.errors import CommandRangeError, RoverLinkError, TransportError
from host_sdk.transport.base import NO_ENDPOINTS, Transport

GROUP = "roverlink.transports"


class PluginEndpoint(Protocol):
    """What a plugin's `open_url` returns (duck-typed: no SDK import needed)."""

    url: str
    virtual: bool

    def read(self, timeout_s: float) -> bytes: ...

    def write(self, data: bytes) -> None: ...

    def close(self) -> None: ...

    def clock(self) -> float: ...


Opener = Callable[[str, int], PluginEndpoint]


def schemes() -> dict[str, importlib.metadata.EntryPoint]:
    """Registered URL schemes and their entry points."""
    return {ep.name: ep for ep in importlib.metadata.entry_points(group=GROUP)}


def scheme_of(url: str) -> str | None:
    """`emu` for "emu://...", None for a device path ("/dev/ttyACM0", "COM3")."""
    head, sep, _rest = url.partition(":")
    return head.lower() if sep and head.isidentifier() and len(head) > 1 else None


def opener(scheme: str) -> Opener | None:
    """The registered opener of `scheme`, loaded on first use (None: not registered)."""
    ep = schemes().get(scheme)
    if ep is None:
        return None
    loaded: Opener = ep.load()
    return loaded


class PluginTransport(Transport):
    """A plugin's endpoint as a Transport. Attributes it does not define are looked up on it."""

    def __init__(self, endpoint: PluginEndpoint) -> None:
        self.endpoint = endpoint
        self.url = endpoint.url
        self.virtual = bool(endpoint.virtual)
        self.profile = getattr(endpoint, "profile", None)
        self.robot_file = getattr(endpoint, "robot_file", None)
        self.device = getattr(endpoint, "device", None)

    @property
    def endpoints(self) -> Mapping[str, str]:
        # Read through: the plugin may attach sensors after opening (roverlink.follow.emulated).
        found = getattr(self.endpoint, "endpoints", None)
        return found if isinstance(found, Mapping) else NO_ENDPOINTS

    def read(self, timeout_s: float) -> bytes:
        try:
            return self.endpoint.read(timeout_s)
        except TransportError:
            raise
        except OSError as exc:
            raise TransportError(f"reading {self.url} failed: {exc}", self.url, exc) from exc

    def write(self, data: bytes) -> None:
        try:
            self.endpoint.write(data)
        except TransportError:
            raise
        except OSError as exc:
            raise TransportError(f"writing {self.url} failed: {exc}", self.url, exc) from exc

    def close(self) -> None:
        self.endpoint.close()

    def clock(self) -> float:
        return self.endpoint.clock()

    def __getattr__(self, name: str) -> Any:
        # Only reached for names the adapter lacks: e.g. the emulator's `locked()`.
        return getattr(self.__dict__["endpoint"], name)


def open_plugin(url: str, baud: int) -> Transport | None:
    """The transport for `url` if a plugin owns its scheme, else None."""
    scheme = scheme_of(url)
    if scheme is None:
        return None
    open_url = opener(scheme)
    if open_url is None:
        return None
    try:
        endpoint = open_url(url, baud)
    except ValueError as exc:
        raise CommandRangeError("url", url, str(exc)) from exc
    except RoverLinkError:
        raise
    except Exception as exc:
        raise TransportError(f"could not open {url}: {exc}", url, exc) from exc
    return endpoint if isinstance(endpoint, Transport) else PluginTransport(endpoint)
