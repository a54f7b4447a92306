"""A multipart JPEG (MJPEG) stream, sans I/O: the parts a network camera sends.

    parser = MjpegParser()
    parser.receive_data(chunk, t)
    for part in parser.parts():         # JpegPart(jpeg, t, headers)
        ...

A part is `--BOUNDARY`, header lines, a blank line, the JPEG, and the next boundary. With a
Content-Length header the JPEG is cut to that length; without one it ends at the JPEG's own end
marker (FF D9). Headers the emulated camera adds: `X-Timestamp` (seconds of its clock) and
`X-Frame` (its counter: gaps are frames this reader missed). Garbage between parts is skipped and
counted; an HTTP response's own header, if fed in, is skipped the same way.
"""

from __future__ import annotations

from dataclasses import dataclass, field

MAX_HEADER = 4096
MAX_FRAME = 8 * 1024 * 1024


@dataclass(frozen=True, slots=True)
class JpegPart:
    jpeg: bytes
    t: float
    """When the part finished arriving (the reader's clock)."""
    headers: dict[str, str] = field(default_factory=dict)
    """Lower-case names."""

    @property
    def frame(self) -> int | None:
        value = self.headers.get("x-frame", "")
        return int(value) if value.isdigit() else None

    @property
    def timestamp(self) -> float | None:
        try:
            return float(self.headers["x-timestamp"])
        except (KeyError, ValueError):
            return None


@dataclass(slots=True)
class MjpegCounters:
    bytes_received: int = 0
    bytes_discarded: int = 0
    parts: int = 0
    bad_parts: int = 0


class MjpegParser:
    def __init__(self) -> None:
        self.counters = MjpegCounters()
        self._buf = bytearray()
        self._parts: list[JpegPart] = []

    def parts(self) -> list[JpegPart]:
        out, self._parts = self._parts, []
        return out

    def receive_data(self, data: bytes, t: float = 0.0) -> None:
        self.counters.bytes_received += len(data)
        buf = self._buf
        buf += data
        while True:
            at = buf.find(b"--")
            if at < 0:
                self._discard(max(0, len(buf) - 1))
                return
            self._discard(at)
            end = buf.find(b"\r\n\r\n")
            if end < 0:
                if len(buf) > MAX_HEADER:
                    self.counters.bad_parts += 1
                    self._discard(2)
                    continue
                return
            headers = _headers(bytes(buf[:end]))
            body_at = end + 4
            length = headers.get("content-length", "")
            if length.isdigit() and int(length) <= MAX_FRAME:
                size = int(length)
                if len(buf) < body_at + size:
                    return
                jpeg = bytes(buf[body_at : body_at + size])
                consumed = body_at + size
            else:
                eoi = buf.find(b"\xff\xd9", body_at)
                if eoi < 0:
                    if len(buf) - body_at > MAX_FRAME:
                        self.counters.bad_parts += 1
                        self._discard(2)
                        continue
                    return
                jpeg = bytes(buf[body_at : eoi + 2])
                consumed = eoi + 2
            del buf[:consumed]
            if jpeg[:2] != b"\xff\xd8":
                self.counters.bad_parts += 1
                continue
            self.counters.parts += 1
            self._parts.append(JpegPart(jpeg, t, headers))

    def _discard(self, n: int) -> None:
        if n > 0:
            del self._buf[:n]
            self.counters.bytes_discarded += n


def _headers(block: bytes) -> dict[str, str]:
    out: dict[str, str] = {}
    for line in block.split(b"\r\n")[1:]:
        name, sep, value = line.partition(b":")
        if sep:
            out[name.strip().lower().decode("latin-1")] = value.strip().decode("latin-1")
    return out
