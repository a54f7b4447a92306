"""Reading recordings back in the tests: the `mcap` reader, and a Foxglove WebSocket client.

Protobuf messages are decoded from the schema each channel carries (a FileDescriptorSet), as
Foxglove does, so the test proves the file and the live stream are self-describing.
"""

from __future__ import annotations

import base64
import contextlib
import json
import struct
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from mcap.decoder import DecoderFactory as McapDecoderFactory
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory
from websockets.sync.client import ClientConnection, connect

from tests.support.wait import wait_until


@dataclass
class Recording:
    schemas: dict[str, tuple[str, str]] = field(default_factory=dict)
    """topic -> (schema name, schema encoding)."""
    encodings: dict[str, str] = field(default_factory=dict)
    counts: dict[str, int] = field(default_factory=dict)
    messages: dict[str, list[tuple[int, Any]]] = field(default_factory=lambda: defaultdict(list))
    """topic -> [(log_time_ns, decoded)] in log-time order (JSON as dicts, protobuf as messages)."""


class JsonDecoderFactory(McapDecoderFactory):
    def decoder_for(self, message_encoding: str, schema: Any) -> Callable[[bytes], Any] | None:
        return json.loads if message_encoding == "json" else None


def read_mcap(path: Path) -> Recording:
    rec = Recording()
    with path.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory(), JsonDecoderFactory()])
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        for channel in summary.channels.values():
            schema = summary.schemas[channel.schema_id]
            rec.schemas[channel.topic] = (schema.name, schema.encoding)
            rec.encodings[channel.topic] = channel.message_encoding
            rec.counts[channel.topic] = summary.statistics.channel_message_counts.get(channel.id, 0)
        for _schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            rec.messages[channel.topic].append((message.log_time, decoded))
    return rec


def protobuf_class(schema_name: str, schema_b64: str) -> Any:
    """The message class described by a base64 FileDescriptorSet (a channel's schema)."""
    fds = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(schema_b64))
    pool = descriptor_pool.DescriptorPool()
    for fd in fds.file:
        pool.Add(fd)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(schema_name))


class LiveClient:
    """A Foxglove WebSocket client: reads the advertised channels, subscribes, decodes messages."""

    def __init__(self, ws: ClientConnection) -> None:
        self.ws = ws
        self.channels: dict[str, dict[str, Any]] = {}
        self._subscriptions: dict[int, dict[str, Any]] = {}
        self.received: dict[str, list[tuple[int, Any]]] = defaultdict(list)

    def _handle(self, frame: str | bytes) -> None:
        if isinstance(frame, str):
            msg = json.loads(frame)
            if msg.get("op") == "advertise":
                for channel in msg["channels"]:
                    self.channels[channel["topic"]] = channel
            return
        if frame[0] != 1:  # 1: a message data frame
            return
        sub_id, time_ns = struct.unpack_from("<IQ", frame, 1)
        channel = self._subscriptions[sub_id]
        payload = frame[13:]
        if channel["encoding"] == "json":
            value: Any = json.loads(payload)
        else:
            value = protobuf_class(channel["schemaName"], channel["schema"]).FromString(payload)
        self.received[channel["topic"]].append((time_ns, value))

    def pump(self, timeout_s: float) -> None:
        """Handle what arrived, waiting up to `timeout_s` for the first frame."""
        with contextlib.suppress(TimeoutError):
            self._handle(self.ws.recv(timeout=timeout_s))
            while True:
                self._handle(self.ws.recv(timeout=0))

    def wait_for(self, what: Callable[[], bool], step: Callable[[], None], timeout_s: float = 20.0) -> bool:
        """Run `step` (e.g. drive the robot one feedback period) and read frames until `what()`."""
        return bool(wait_until(what, timeout_s, step=lambda: (step(), self.pump(0.02)), fail=False))

    def subscribe(self, *topics: str) -> None:
        subs = []
        for topic in topics:
            channel = self.channels[topic]
            sub_id = len(self._subscriptions) + 1
            self._subscriptions[sub_id] = channel
            subs.append({"id": sub_id, "channelId": channel["id"]})
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))


def open_live(port: int) -> ClientConnection:
    """A connection to a Foxglove SDK server (use it as a context manager)."""
    return connect(f"ws://127.0.0.1:{port}", subprotocols=["foxglove.sdk.v1"])
