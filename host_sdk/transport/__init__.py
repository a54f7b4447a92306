"""Transports: the byte pipes a session runs over.

A transport is three calls: `read(timeout_s)` returns the bytes that arrived (empty after the
timeout), `write(data)` sends bytes, `close()` releases the port. `clock()` is the time base the
session uses with it (the host's monotonic clock, or the emulator's virtual clock).

- `SerialTransport` opens anything pyserial's `serial_for_url` opens: a device path
  (`/dev/ttyACM0`, `COM3`), `socket://host:port`, `loop://`, `spy://PORT` (logs the traffic).
- `EmulatorTransport` talks to an in-process `emulator.Emulator`, either paced by wall time
  (`clock="real"`: feels like a robot) or on its virtual clock (`clock="virtual"`: `read()` moves
  virtual time forward, so tests are deterministic and as fast as the CPU allows).

`open_transport(url, baud)` picks one by URL; `emu://PROFILE?seed=3&faults=...&clock=virtual`
builds an emulator (see `parse_emu_url`).
"""

from host_sdk.transport.base import Transport
from host_sdk.transport.emulated import EmulatorOptions, EmulatorTransport, parse_emu_url
from host_sdk.transport.serial_port import SerialTransport, open_transport

__all__ = ["EmulatorOptions", "EmulatorTransport", "SerialTransport", "Transport", "open_transport", "parse_emu_url"]
