"""The wire format's runtime, independent of any message: COBS, CRC-16 with CRC_EXTRA, and the
message base class with its field metadata.

protocol.generated holds the messages; protocol.framing is the frame encoder and decoder over them.
"""
