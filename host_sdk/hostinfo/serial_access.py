"""Serial ports and whether this user may open them (on Linux: the device's group, dialout)."""

from __future__ import annotations

import grp
import os
import pwd
from dataclasses import dataclass

from host_sdk.ports import PortInfo, list_serial_ports


@dataclass(frozen=True, slots=True)
class PortAccess:
    port: PortInfo
    allowed: bool
    """This process may read and write it."""
    group: str | None
    """The device node's group (dialout on Debian and Ubuntu)."""
    in_group: bool
    """This process has that group."""
    listed: bool
    """The user is a member in /etc/group, which takes effect at the next login."""


def user_name() -> str:
    try:
        return pwd.getpwuid(os.getuid()).pw_name
    except KeyError:
        return str(os.getuid())


def port_access(port: PortInfo) -> PortAccess:
    try:
        st = os.stat(port.device)
        group = grp.getgrgid(st.st_gid)
    except (OSError, KeyError):
        return PortAccess(port, os.access(port.device, os.R_OK | os.W_OK), None, False, False)
    allowed = os.access(port.device, os.R_OK | os.W_OK)
    in_group = st.st_gid in os.getgroups() or st.st_gid == os.getgid()
    return PortAccess(port, allowed, group.gr_name, in_group, user_name() in group.gr_mem)


def serial_access() -> list[PortAccess]:
    return [port_access(p) for p in list_serial_ports()]
