"""A TCP endpoint on 127.0.0.1: pyserial opens it as `serial.serial_for_url("socket://127.0.0.1:PORT")`.

One host at a time; a connection is "opening the port" (DTR reset), closing it is closing the port.
"""

from __future__ import annotations

import select
import socket as _socket


class SocketEndpoint:
    def __init__(self, port: int = 0, host: str = "127.0.0.1") -> None:
        self._server = _socket.socket(_socket.AF_INET, _socket.SOCK_STREAM)
        self._server.setsockopt(_socket.SOL_SOCKET, _socket.SO_REUSEADDR, 1)
        self._server.bind((host, port))
        self._server.listen(1)
        self._server.setblocking(False)
        self.port = self._server.getsockname()[1]
        self.name = f"socket://{host}:{self.port}"
        self._client: _socket.socket | None = None

    def poll(self) -> tuple[bool, int]:
        """(a host is connected now, how many connections were accepted since the last poll)."""
        if self._client is not None:
            return True, 0
        try:
            client, _ = self._server.accept()
        except BlockingIOError:
            return False, 0
        client.setblocking(False)
        client.setsockopt(_socket.IPPROTO_TCP, _socket.TCP_NODELAY, 1)
        self._client = client
        return True, 1

    def on_connect(self) -> None:
        """Nothing is buffered before a connection exists."""

    def _drop(self) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None

    def read(self) -> bytes:
        if self._client is None:
            return b""
        try:
            data = self._client.recv(4096)
        except BlockingIOError:
            return b""
        except OSError:
            self._drop()
            return b""
        if not data:
            self._drop()
        return data

    def write(self, data: bytes) -> None:
        if self._client is None:
            return
        try:
            self._client.sendall(data)
        except OSError:
            self._drop()

    def wait(self, timeout_s: float) -> None:
        fd = self._client if self._client is not None else self._server
        select.select([fd], [], [], timeout_s)

    def close(self) -> None:
        self._drop()
        self._server.close()
