"""Transports: the byte pipes a session runs over, and the sensor drivers' ports (host_sdk.sensors).

A transport is three calls: `read(timeout_s)` returns the bytes that arrived (empty after the
timeout), `write(data)` sends bytes, `close()` releases the port. `clock()` is the time base the
session uses with it (the host's monotonic clock, or the emulator's virtual clock). `set_dtr(level)`
and `set_baud(baud)` serve the sensors (the RPLIDAR's motor line, a JY901's baud change); a
transport without modem lines ignores them.

- `SerialTransport` opens anything pyserial's `serial_for_url` opens: a device path
  (`/dev/ttyACM0`, `COM3`), `socket://host:port`, `loop://`, `spy://PORT` (logs the traffic).
- Other URL schemes are opened by plugins registered in the `roverlink.transports` entry point
  group (host_sdk.transport.plugins): the emulator registers `emu://`, an in-process emulated
  robot on the wall clock or on its virtual clock (docs/emulator.md lists its URL parameters),
  and `emudev://`, the sensors next to it.

`open_transport(url, baud)` picks one by URL.
"""

from host_sdk.transport.base import Transport
from host_sdk.transport.plugins import PluginTransport
from host_sdk.transport.serial_port import SerialTransport, open_transport

__all__ = ["PluginTransport", "SerialTransport", "Transport", "open_transport"]
