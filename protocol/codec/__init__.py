"""The wire format's runtime, independent of any message: COBS, CRC-16 with CRC_EXTRA, the message
base class with its field metadata, and the frame encoder/decoder over a table of messages.

protocol.generated holds the messages; protocol.framing binds the decoder to them.
"""
