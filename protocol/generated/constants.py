# DO NOT EDIT: generated from protocol/spec/roverlink.toml by `python -m protocol generate`.
# spec hash: 0xBDF31659
"""Protocol constants."""

from typing import Final

PROTOCOL_VERSION: Final = 2
SPEC_HASH: Final = 0xBDF31659
MAX_PAYLOAD: Final = 64
MAX_BODY: Final = 68
"""Longest decoded frame: msg_id, seq, payload, CRC."""
MAX_FRAME: Final = 70
"""Longest frame on the wire, delimiter included."""
WATCHDOG_DEFAULT_MS: Final = 250
"""Watchdog period used when HELLO asks for 0 and the stored config has none."""
WATCHDOG_MIN_MS: Final = 50
"""Shortest watchdog period the firmware grants (five control ticks)."""
WATCHDOG_MAX_MS: Final = 2000
"""Longest watchdog period the firmware grants."""
CONTROL_RATE_HZ: Final = 100
"""Control loop rate: PID, limits, watchdog check and stream feedback scheduling run once per tick."""
LOCKSTEP_QUEUE: Final = 2
"""Setpoints an ARMED lockstep session holds for its next ticks, applied one per tick in arrival order; one arriving to a full queue replaces the newest. A host may so stay a tick ahead, and be late by most of two ticks without a tick going unanswered. Stream mode holds one (latest wins)."""
FEEDBACK_HZ_DEFAULT: Final = 50
"""Stream feedback rate when HELLO asks for 0."""
FEEDBACK_HZ_MAX: Final = 100
"""Highest stream feedback rate (one FEEDBACK per control tick)."""
HELLO_INTERVAL_MS: Final = 100
"""How often the host repeats HELLO until IDENTITY arrives."""
WHEEL_COUNT: Final = 2
"""Wheel channels carried in setpoints and feedback; a single-motor robot uses channel 0."""
PID_ALL_WHEELS: Final = 255
"""SET_PID wheel index that addresses every wheel at once."""
